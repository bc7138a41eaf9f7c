"""rockyade crosscheck: the statistics on constructed data with known answers, a small real
cross-check (Housner and the reference DEM on short records), resume without repeating a run,
and result sets that are replaced whole, never mixed."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from rockyade.analysis.crosscheck_statistics import (
    ABOVE,
    ALL_FAILED,
    BRACKETED,
    MAX_EXTENSIONS,
    collapse_summary,
    median_interval,
    next_levels,
    pair_verdict,
    paired_ratios,
    scan_levels,
    verdict_agreement,
)
from rockyade.errors import BatchInterruptedError, InputError

from .conftest import external_records_dir, needs_records
from .processes import sigint_default

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def search(collapses, scan, resolution=0.01, **limits):
    """Run a collapse search against an oracle ``collapses(level) -> bool``; its outcomes."""
    outcomes: dict[float, bool | None] = {}
    for _ in range(200):
        levels = next_levels(outcomes, scan, resolution, **limits)
        if not levels:
            return outcomes
        for level in levels:
            outcomes[level] = collapses(level)
    raise AssertionError("the search did not end")


# ---------------------------------------------------------------------- the statistics


@pytest.mark.parametrize("threshold", [0.27, 0.5, 0.93, 1.61])
def test_bisection_finds_a_known_threshold(threshold):
    scan = scan_levels(0.25, 2.0, 7)
    outcomes = search(lambda x: x >= threshold, scan, 0.01)
    found = collapse_summary(outcomes, scan)
    assert found.status == BRACKETED
    assert found.bracket_low < threshold <= found.bracket_high
    assert found.bracket_high / found.bracket_low <= 1.01 + 1e-9
    assert found.collapse_intensity == found.bracket_high
    if threshold < 1.5:  # a simply connected region: every scanned level above the first collapse collapses
        assert found.survived_above_fraction == 0.0
    else:  # the first scanned collapse is the top level: none above it
        assert math.isnan(found.survived_above_fraction)
    assert found.runs == len(outcomes) <= 7 + 6  # the scan, then bisection from a step of 2**0.5 to 1 %


def test_overturning_region_not_simply_connected():
    scan = scan_levels(0.25, 2.0, 7)  # 0.25, 0.354, 0.5, 0.707, 1, 1.41, 2
    # collapses from 0.4 to 0.8 and from 1.9 up: stands at 1 and 1.41
    outcomes = search(lambda x: 0.4 <= x < 0.8 or x >= 1.9, scan, 0.01)
    found = collapse_summary(outcomes, scan)
    assert found.bracket_low < 0.4 <= found.bracket_high
    assert found.survived_above_fraction == pytest.approx(2 / 4)  # above 0.5: of 0.707, 1, 1.41, 2, 1 and 1.41 stood


def test_search_extends_then_gives_up():
    scan = scan_levels(0.25, 2.0, 7)
    outcomes = search(lambda x: False, scan, highest=100.0)
    assert sum(1 for v in outcomes if v > 2.0) == MAX_EXTENSIONS
    found = collapse_summary(outcomes, scan)
    assert found.status == ABOVE and math.isnan(found.collapse_intensity)
    assert found.bracket_low == pytest.approx(2.0 * 2**MAX_EXTENSIONS)
    # a threshold just above the scan is found by one extension
    found = collapse_summary(search(lambda x: x >= 2.5, scan), scan)
    assert found.bracket_low < 2.5 <= found.bracket_high and found.status == BRACKETED
    # below the scan, and a limit on the load factor that stops the extension
    found = collapse_summary(search(lambda x: x >= 0.2, scan), scan)
    assert found.bracket_low < 0.2 <= found.bracket_high
    assert search(lambda x: x >= 0.2, scan, lowest=0.2) == {v: True for v in scan}


def test_failed_runs_have_no_verdict():
    scan = [1.0, 2.0]
    found = collapse_summary({1.0: None, 2.0: True}, scan)
    assert found.failed == 1 and found.status != BRACKETED


def test_bootstrap_interval_contains_the_known_median_ratio():
    rng = np.random.default_rng(7)
    ratios = 1.1 * np.exp(rng.normal(0.0, 0.08, 61))
    true_median = 1.1
    m = median_interval(ratios)
    assert m.low < true_median < m.high
    assert m.low <= m.median <= m.high and m.n == 61
    assert m.high - m.low < 0.1
    assert median_interval(ratios) == m  # seeded: the same values give the same interval
    same = median_interval([1.2, 1.2, 1.2])
    assert (same.median, same.low, same.high) == (1.2, 1.2, 1.2)
    assert math.isnan(median_interval([1.0]).low) and median_interval([]).n == 0


def test_paired_ratios_and_verdict_agreement():
    a = {"r1": 0.5, "r2": 0.8, "r3": math.nan}
    b = {"r1": 0.25, "r2": 0.8, "r3": 0.3, "r4": 1.0}
    assert paired_ratios(a, b) == {"r1": 2.0, "r2": 1.0}
    va = {("r1", 0.5): True, ("r1", 1.0): True, ("r2", 0.5): None, ("r2", 1.0): False}
    vb = {("r1", 0.5): False, ("r1", 1.0): True, ("r2", 0.5): True, ("r2", 1.0): False}
    assert verdict_agreement(va, vb) == (2, 3)


def test_pair_verdict_says_nothing_below_the_dt_change():
    tight = median_interval(1.03 * np.exp(np.random.default_rng(1).normal(0, 0.01, 40)))
    assert pair_verdict("a", "b", tight, 0.05).verdict == "agree"
    wide_gap = median_interval(1.2 * np.exp(np.random.default_rng(2).normal(0, 0.01, 40)))
    assert pair_verdict("a", "b", wide_gap, 0.05).verdict == "differ"
    moved = pair_verdict("a", "b", wide_gap, 0.05, {"a": 0.3, "b": 0.0})
    assert moved.verdict == "unresolved" and "says nothing" in moved.sentence
    assert (
        pair_verdict("a", "b", median_interval([0.7, 0.7, 1.0, 1.0, 1.0, 1.0]), 0.05, {"a": 0.0}).verdict
        == "inconclusive"
    )
    caveat = pair_verdict("a", "b", tight, 0.05, {"b": 0.08})
    assert caveat.verdict == "agree" and "not converged" in caveat.sentence


# ---------------------------------------------------------------------- a real cross-check


def write_records(folder: Path, count: int = 2) -> Path:
    """Short records (3 s at 0.01 s, m/s^2): a sine pulse of a period each, with noise."""
    folder.mkdir(parents=True, exist_ok=True)
    t = np.arange(0.0, 3.0 + 1e-9, 0.01)
    for k, period in enumerate((0.45, 0.8, 1.1)[:count]):
        rng = np.random.default_rng(k + 1)
        a = 3.0 * np.sin(2 * np.pi * t / period) * np.exp(-(((t - 1.2) / 0.6) ** 2))
        a += 0.3 * rng.standard_normal(t.size) * np.exp(-(((t - 1.2) / 0.8) ** 2))
        lines = [f"# test record {k + 1}", "t_s,accel_m_s2"] + [f"{x:.4f},{y:.6g}" for x, y in zip(t, a, strict=True)]
        (folder / f"rec{k + 1}.csv").write_text("\n".join(lines) + "\n")
    return folder


def small_plan(records: Path, dt_factors=(1.0, 0.5)):
    from rockyade.assess import parse_measure, records_in_folder
    from rockyade.runner import Executor
    from rockyade.scene import load_scene
    from rockyade.studies.crosscheck import crosscheck_plan

    return crosscheck_plan(
        load_scene(EXAMPLES / "specimen1_record.toml"),
        records_in_folder(records),
        parse_measure("pga"),
        ["housner", "reference"],
        levels=[0.3, 0.6, 1.2],
        dt_factors=dt_factors,
        resolution=0.1,
        executor=Executor("threads", 1),
        tail_s=1.0,
        progress=False,
    )


def run(plan, out: Path, resume: bool = False):
    from rockyade.runner import Executor
    from rockyade.studies.crosscheck import run_crosscheck

    return run_crosscheck(plan, out, Executor("threads", 1), resume=resume, progress=False, say=lambda _s: None)


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    return write_records(tmp_path_factory.mktemp("records") / "records")


@pytest.fixture(scope="module")
def plan(records):
    return small_plan(records)


@pytest.fixture(scope="module")
def complete(plan, tmp_path_factory):
    out = tmp_path_factory.mktemp("cc") / "out"
    return out, run(plan, out)


@pytest.mark.slow
def test_small_real_crosscheck(complete, plan):
    out, summary = complete
    assert summary.partial is False and summary.verdicts
    from rockyade.studies.crosscheck import RESULT_FILES, journal_dir

    for name in RESULT_FILES:
        assert (out / name).is_file(), name
    assert not journal_dir(out).exists()  # the set complete, the journal goes
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == sorted(RESULT_FILES)
    ci = pd.read_csv(out / "collapse_intensities.csv")
    for column in (
        "record",
        "solver",
        "dt_factor",
        "collapse_intensity",
        "intensity_unit",
        "bracket_low",
        "bracket_high",
        "survived_above_fraction",
    ):
        assert column in ci.columns
    assert len(ci) == 2 * 2 * 2  # records x solvers x dt factors
    done = ci[ci.status == BRACKETED]
    assert len(done) >= 6
    assert (done.bracket_high / done.bracket_low <= 1.1 + 1e-9).all()
    assert (done.collapse_intensity == done.bracket_high).all() and set(ci.intensity_unit) == {"g"}
    # each bracket is what the runs say: the top collapsed, the bottom stood
    runs = pd.read_csv(out / "runs.csv")
    for _, r in done.iterrows():
        mine = runs[(runs.record == r.record) & (runs.solver == r.solver) & (runs.dt_factor == r.dt_factor)]
        assert bool(mine.loc[np.isclose(mine.pga_g, r.bracket_high), "collapsed"].iloc[0])
        assert not bool(mine.loc[np.isclose(mine.pga_g, r.bracket_low), "collapsed"].iloc[0])
    pairs = pd.read_csv(out / "pairs.csv")
    assert set(pairs.kind) == {"solvers", "dt"}
    solvers = pairs[pairs.kind == "solvers"]
    assert len(solvers) == 2 and (solvers.solver_a != solvers.solver_b).all()
    for _, r in solvers.iterrows():  # the ratio is the median of the per-record ratios
        a = ci[(ci.solver == r.solver_a) & (ci.dt_factor == r.dt_factor_a)].set_index("record").collapse_intensity
        b = ci[(ci.solver == r.solver_b) & (ci.dt_factor == r.dt_factor_b)].set_index("record").collapse_intensity
        assert r.median_ratio == pytest.approx(float(np.nanmedian(a / b)))
        assert 0 < r.same_verdict_share <= 1 and r.compared_runs == 2 * 3
    data = json.loads((out / "crosscheck.json").read_text())
    assert data["partial"] is False and data["runs_reused"] == 0
    assert data["runs_made"] == len(runs)
    assert {(f["solver"], f["dt_factor"]) for f in data["fragility"]} == {
        (s, f) for s in ("housner", "reference") for f in (1.0, 0.5)
    }
    index = (out / "index.md").read_text()
    assert "## Verdicts" in index and "PARTIAL" not in index and "housner / reference" in index


@pytest.mark.slow
def test_resume_after_an_interruption_repeats_no_run(plan, complete, tmp_path, monkeypatch):
    import rockyade.studies.crosscheck as cc

    reference_out, _ = complete
    total = len(pd.read_csv(reference_out / "runs.csv"))
    real = cc.search.run_study
    calls = {"n": 0}

    def stop_at_the_third_round(*args, **kwargs):
        calls["n"] += 1
        if calls["n"] == 3:
            raise BatchInterruptedError(0, len(args[0]), None)
        return real(*args, **kwargs)

    monkeypatch.setattr(cc.search, "run_study", stop_at_the_third_round)
    out = tmp_path / "out"
    with pytest.raises(BatchInterruptedError):
        run(plan, out)
    stage = cc.journal_dir(out)
    partial = json.loads((stage / "crosscheck.json").read_text())
    assert partial["partial"] is True and not (out / "crosscheck.json").exists()
    assert "PARTIAL" in (stage / "index.md").read_text()
    first = {p: p.stat().st_mtime_ns for p in stage.rglob("runs/*.json")}
    assert 0 < len(first) < total
    for path in first:  # each run in the journal says its time-step factor (its folder's) and step
        meta = json.loads(path.read_text())
        assert meta["dt_factor"] == float(path.parent.parent.name.removeprefix("dt")) and meta["dt_s"] > 0
    assert set(pd.read_csv(reference_out / "runs.csv").dt_factor) == {1.0, 0.5}
    monkeypatch.setattr(cc.search, "run_study", real)
    written: list[str] = []
    real_write = cc.search.run_study

    def watch(tasks, *args, **kwargs):  # every run the resumed study makes
        written.extend(str(t.scene_hash) + repr(t.solver) for t in tasks)
        return real_write(tasks, *args, **kwargs)

    monkeypatch.setattr(cc.search, "run_study", watch)
    run(plan, out, resume=True)
    data = json.loads((out / "crosscheck.json").read_text())
    assert data["runs_reused"] == len(first)
    assert data["runs_made"] == total - len(first) == len(written)  # no run made twice
    same = pd.read_csv(out / "collapse_intensities.csv")
    pd.testing.assert_frame_equal(same, pd.read_csv(reference_out / "collapse_intensities.csv"))


@pytest.mark.slow
def test_resume_after_kill_replays_from_disk(plan, complete, tmp_path, monkeypatch):
    """A process killed mid-study (no summary written): the runs on disk are all it left."""
    import rockyade.studies.crosscheck as cc

    real = cc.search.run_study
    calls = {"n": 0}

    def killed(*args, **kwargs):
        calls["n"] += 1
        if calls["n"] == 2:
            raise SystemExit(137)  # stands for SIGKILL: nothing after this line runs
        return real(*args, **kwargs)

    monkeypatch.setattr(cc.search, "run_study", killed)
    out = tmp_path / "out"
    with pytest.raises(SystemExit):
        run(plan, out)
    assert not (cc.journal_dir(out) / "crosscheck.json").exists() and not (out / "crosscheck.json").exists()
    done = len(list(cc.journal_dir(out).rglob("runs/*.json")))
    monkeypatch.setattr(cc.search, "run_study", real)
    run(plan, out, resume=True)
    data = json.loads((out / "crosscheck.json").read_text())
    assert data["runs_reused"] == done > 0


def test_a_second_study_on_the_same_out_never_mixes(plan, complete, records, tmp_path, monkeypatch):
    import shutil

    import rockyade.studies.crosscheck as cc

    out = tmp_path / "out"
    shutil.copytree(complete[0], out)
    before = (out / "crosscheck.json").read_bytes()
    other_records = write_records(tmp_path / "one", count=1)
    other = small_plan(other_records, dt_factors=(1.0,))
    # a study that crashes part-way leaves the complete earlier set as it was
    real = cc.search.run_study
    calls = {"n": 0}

    def crash(*args, **kwargs):
        calls["n"] += 1
        if calls["n"] == 2:
            raise OSError(28, "No space left on device")
        return real(*args, **kwargs)

    monkeypatch.setattr(cc.search, "run_study", crash)
    with pytest.raises(OSError):
        run(other, out)
    assert (out / "crosscheck.json").read_bytes() == before
    monkeypatch.setattr(cc.search, "run_study", real)
    with pytest.raises(InputError, match="--resume"):  # a resume of another study is refused
        run(small_plan(other_records, dt_factors=(1.0, 0.5)), out, resume=True)
    run(other, out)  # without --resume: the unfinished study is discarded, the new set replaces the old
    data = json.loads((out / "crosscheck.json").read_text())
    assert data["plan"]["dt_factors"] == [1.0] and data["runs_reused"] == 0
    ci = pd.read_csv(out / "collapse_intensities.csv")
    assert set(ci.record) == {"rec1.csv"} and set(ci.dt_factor) == {1.0}
    assert data["runs_made"] == len(pd.read_csv(out / "runs.csv"))  # no run of the old set left
    assert not list(out.rglob("runs/*.json")) and not cc.journal_dir(out).exists()
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == sorted(cc.RESULT_FILES)


@pytest.mark.slow
def test_ctrl_c_mid_run_leaves_the_previous_set_intact(complete, records, tmp_path, capsys):
    """A real ``rockyade crosscheck`` process sent SIGINT once its first run is in the journal:
    exit 130, the earlier complete set byte for byte as it was (no file of the new study in it,
    nothing that looks complete), the partial summary in the journal; --resume then finishes."""
    import os
    import shutil
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "out"
    shutil.copytree(complete[0], out)
    before = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    argv = [
        sys.executable,
        "-m",
        "rockyade",
        "crosscheck",
        str(EXAMPLES / "specimen1_record.toml"),
        "--records",
        str(records),
        "--levels",
        "0.3,0.6,1.2",
        "--resolution",
        "0.02",
        "--dt-factors",
        "1",
        "--tail",
        "1",
        "--workers",
        "1",
        "--quiet",
        "--out",
        str(out),
    ]
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])}
    proc = subprocess.Popen(
        argv, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, preexec_fn=sigint_default
    )
    journal = out / "partial"
    deadline = time.monotonic() + 600
    while not list(journal.rglob("runs/*.json")) and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    assert proc.poll() is None, proc.communicate()[0]
    proc.send_signal(signal.SIGINT)
    text = proc.communicate(timeout=600)[0]
    assert proc.returncode == 130, text
    after = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    assert after == before  # the previous set untouched, nothing of the new study mixed in
    assert json.loads((journal / "crosscheck.json").read_text())["partial"] is True
    assert not list(out.glob(".set.*"))  # no staged set left behind
    # the message says what runs.csv lists (the finished runs: before, "lists them" after the
    # unfinished count) and its count is runs.csv's; the --resume it names exists (run below)
    said = re.search(
        r"interrupted: (\d+) run\(s\) finished, \d+ of the interrupted round unfinished; (\S+) lists the finished runs",
        text,
    )
    assert said is not None and "--resume" in text, text
    assert Path(said.group(2)) == journal / "runs.csv" and len(pd.read_csv(said.group(2))) == int(said.group(1))
    from rockyade.cli import main

    capsys.readouterr()
    # the resume runs in this process (the same `main`, absolute paths): only the stop needs a real one
    assert main([*argv[3:], "--resume"]) == 0, capsys.readouterr()
    data = json.loads((out / "crosscheck.json").read_text())
    assert data["partial"] is False and data["runs_reused"] >= 1 and data["plan"]["dt_factors"] == [1.0]
    assert not journal.exists()


def test_out_that_is_a_link_or_a_file_is_refused(tmp_path):
    from rockyade.studies.crosscheck import check_out, journal_dir

    mine = tmp_path / "mine"
    mine.mkdir()
    (tmp_path / "link").symlink_to(mine)
    with pytest.raises(InputError, match="symbolic link"):
        check_out(tmp_path / "link")
    (tmp_path / "file").write_text("x")
    with pytest.raises(InputError, match="is a file"):
        check_out(tmp_path / "file")
    journal_dir(mine).symlink_to(tmp_path)  # the journal, cleared without --resume, must not be a link
    with pytest.raises(InputError, match="symbolic link"):
        check_out(mine)


WARM_UP_CHECK = """
import sys
from pathlib import Path
from rockyade.assess import parse_measure, records_in_folder
from rockyade.runner import Executor
from rockyade.scene import load_scene
from rockyade.studies.crosscheck import Study, crosscheck_plan
from rockyade.kernel.runs import simulate_runs
from rockyade.kernel.single import simulate_single
plan = crosscheck_plan(load_scene(Path(sys.argv[1])), records_in_folder(sys.argv[2]), parse_measure("pga"),
    ["housner", "reference"], levels=[0.3, 0.6], dt_factors=(1.0, 0.5), resolution=0.2,
    executor=Executor("threads", 1), progress=False)
assert not simulate_runs.signatures and not simulate_single.signatures
Study(plan, Path(sys.argv[3]), Executor("local", 2), progress=False, allow_large=False, say=print).warm_up()
print(len(simulate_runs.signatures), len(simulate_single.signatures))
"""


@pytest.mark.slow
def test_warm_up_loads_the_kernels_the_workers_run(records, tmp_path):
    """In a fresh process, the study's warm-up loads the reference DEM's grouped and single-run
    kernels as the batch runs them (the lean solver, without energy terms): the workers forked
    for each round inherit them instead of loading (or compiling) them again, each."""
    import os
    import subprocess
    import sys

    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])}
    argv = [sys.executable, "-c", WARM_UP_CHECK, str(EXAMPLES / "specimen1_record.toml"), str(records), str(tmp_path)]
    done = subprocess.run(argv, env=env, capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr
    grouped, single = (int(x) for x in done.stdout.split()[-2:])
    assert grouped >= 1 and single >= 1


def test_cost_line_counts_the_start_up(plan):
    from rockyade.studies.crosscheck import ROUND_OVERHEAD_S

    line = plan.cost_line(2)
    assert "start-up" in line and f"{plan.rounds()} rounds" in line
    assert plan.rounds() >= 2 * len(plan.dt_factors)  # the scan and at least one bisection per factor
    assert plan.startup_s() >= plan.rounds() * ROUND_OVERHEAD_S


# ---------------------------------------------------------------------- the command


def cli(*argv: str) -> int:
    from rockyade.cli import main

    return main(list(argv))


@pytest.mark.parametrize(
    ("argv", "option"),
    [
        (["--solvers", "housner"], "--solvers"),
        (["--solvers", "housner,housner"], "--solvers"),
        (["--solvers", "housner,nosuch"], "--solvers"),
        (["--dt-factors", "0.5,1"], "--dt-factors"),
        (["--dt-factors", "1,1.5"], "--dt-factors"),
        (["--resolution", "0"], "--resolution"),
        (["--tolerance", "nan"], "--tolerance"),
        (["--yade-timeout", "5"], "--yade-timeout"),
        (["--workers", "0"], "--workers"),
        (["--count", "3"], "--count"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(argv, option, records, tmp_path, capsys):
    code = cli(
        "crosscheck",
        str(EXAMPLES / "specimen1_record.toml"),
        "--records",
        str(records),
        "--out",
        str(tmp_path / "o"),
        "--quiet",
        *argv,
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and option in err[0], err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("kind", ["linked folder", "real folder", "link without suffix", "dangling link"])
def test_records_folder_refuses_what_it_would_skip_naming_it(kind, records, tmp_path, capsys):
    """A records folder holding a subfolder (linked or real) or a link that is not a record
    link: exit 2, one line naming the entry; nothing is skipped silently or followed."""
    import shutil

    folder = tmp_path / "recs"
    shutil.copytree(records, folder)
    shared = write_records(tmp_path / "shared", count=3)
    entry = {
        "linked folder": folder / "more",
        "real folder": folder / "more",
        "link without suffix": folder / "rec3",
        "dangling link": folder / "gone.csv",
    }[kind]
    if kind == "linked folder":
        entry.symlink_to(shared)
    elif kind == "real folder":
        entry.mkdir()
        shutil.copy(shared / "rec3.csv", entry / "rec3.csv")
    elif kind == "link without suffix":
        entry.symlink_to(shared / "rec3.csv")
    else:
        entry.symlink_to(tmp_path / "nothing.csv")
    code = cli(
        "crosscheck",
        str(EXAMPLES / "specimen1_record.toml"),
        "--records",
        str(folder),
        "--out",
        str(tmp_path / "o"),
        "--quiet",
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "--records" in err[0] and str(entry) in err[0], err
    assert not (tmp_path / "o").exists()


def test_records_folder_follows_links_to_record_files_and_ignores_hidden_entries(records, tmp_path):
    from rockyade.assess import records_in_folder

    folder = tmp_path / "links"
    folder.mkdir()
    for path in sorted(records.iterdir()):
        (folder / path.name).symlink_to(path)
    (folder / ".cache").mkdir()
    (folder / "__pycache__").mkdir()  # Python's, beside an imported script of the folder
    (folder / "README.md").write_text("two records")
    motions = records_in_folder(folder)
    assert motions.count == 2 and [Path(p) for p in motions.files] == sorted(p.resolve() for p in records.iterdir())


def test_command_writes_the_set(records, tmp_path, capsys):
    out = tmp_path / "cc"
    code = cli(
        "crosscheck",
        str(EXAMPLES / "specimen1_record.toml"),
        "--records",
        str(records),
        "--solvers",
        "housner,reference",
        "--levels",
        "0.3,0.6,1.2",
        "--resolution",
        "0.2",
        "--dt-factors",
        "1",
        "--tail",
        "1",
        "--out",
        str(out),
        "--quiet",
        "--workers",
        "1",
    )
    text = capsys.readouterr().out
    assert code == 0, text
    assert "cost: about" in text and "housner / reference" in text
    assert (out / "index.md").is_file() and (out / "crosscheck.png").stat().st_size > 10_000


def test_figure_is_a_display_object(complete):
    from matplotlib.figure import Figure

    from rockyade.figures.canvas import file_figure
    from rockyade.figures.paired_ratios import PairedRatios

    pairs = pd.read_csv(complete[0] / "pairs.csv")
    fig, ax = file_figure()
    display = PairedRatios.from_pairs(pairs, "pga").plot(ax=ax)
    assert display.ax_ is ax and display.figure_ is fig and isinstance(fig, Figure)
    assert len(display.labels) == len(pairs) and ax.get_xscale() == "log"
    with pytest.raises(InputError, match="pairs"):
        PairedRatios.from_pairs(pairs.drop(columns=["median_ratio"]))


# ---------------------------------------------------------------------- compare


def test_compare_never_compares_a_solver_with_itself_and_gives_a_verdict(tmp_path, capsys):
    from rockyade.analysis.compare import compare, verdict
    from rockyade.scene import load_scene
    from rockyade.solvers import make_solver

    scene = load_scene(EXAMPLES / "specimen1_record.toml")
    results = {n: make_solver(n).run(scene) for n in ("housner", "reference")}
    table = compare(scene, results, "reference")
    assert set(table.solver) == {"housner"}  # no row of the reference against itself
    finer = {n: make_solver(n, dt_factor=0.5).run(scene) for n in results}
    line = verdict(scene, results, "reference", finer)
    row = table[table.metric == "max_abs_theta_rad"].iloc[0]
    gap = abs(row.value - row.reference_value) / max(row.value, row.reference_value)
    assert line.startswith("same outcome (completed); peak |theta| within ")
    assert f"{100 * gap:.1f} %" in line and "halving the step changed" in line
    # a constructed case: the finer step moves a solver more than the solvers differ
    assert "says nothing" in verdict(scene, results, "reference", {"housner": results["reference"]})
    assert verdict(scene, results, "reference").endswith("the time step not checked")
    code = cli(
        "compare",
        str(EXAMPLES / "specimen1_record.toml"),
        "--solvers",
        "housner,reference",
        "--dt-factor",
        "0.5",
        "--out",
        str(tmp_path / "c"),
    )
    out = capsys.readouterr().out
    assert code == 0 and "verdict: same outcome" in out
    assert "cost: 4 run(s), about" in out and "housner at dt x 0.25" in out  # before any run
    assert (tmp_path / "c" / "specimen1_record_housner_halfdt.json").is_file()
    assert json.loads((tmp_path / "c" / "specimen1_record_housner.json").read_text())["dt_factor"] == 0.5


def test_compare_refuses_a_single_solver(tmp_path, capsys):
    """compare never compares a solver with itself: with one solver it wrote a table of that
    solver against itself (zero differences) and the verdict "same outcome"; now refused naming
    solvers, exit 2, nothing written."""
    code = cli("compare", str(EXAMPLES / "specimen1_free.toml"), "--solvers", "housner", "--out", str(tmp_path / "c"))
    err = capsys.readouterr().err
    assert (
        code == 2 and err.startswith("rockyade: error: solvers: must name at least two solvers") and "'housner'" in err
    )
    assert not (tmp_path / "c").exists()


def test_compare_refuses_an_out_that_holds_a_study(tmp_path, capsys):
    """compare writes loose files (<scene>_<solver>.csv, ...): into a study's folder (here a
    fragility's set) they would be mixed with its set; refused naming --out and the study, before
    any run, the folder left as it was."""
    out = tmp_path / "frag"
    out.mkdir()
    (out / "fragility.json").write_text("{}")
    code = cli("compare", str(EXAMPLES / "specimen1_free.toml"), "--solvers", "housner,reference", "--out", str(out))
    err = capsys.readouterr().err
    assert code == 2 and "--out" in err and "'rockyade fragility'" in err and "Traceback" not in err
    assert [p.name for p in out.iterdir()] == ["fragility.json"]


def test_free_rocking_verdict_compares_the_peaks_after_release():
    """In free rocking max |theta| is the release angle for every solver: the verdict compares the
    peaks after the release (the table's peak1-4), and a zero step change with a zero gap between
    solvers is agreement, not "says nothing"."""
    from rockyade.analysis.compare import FREE_PEAKS, compare, verdict
    from rockyade.scene import load_scene
    from rockyade.solvers import make_solver

    scene = load_scene(EXAMPLES / "specimen1_free.toml")
    results = {n: make_solver(n).run(scene) for n in ("housner", "reference")}
    table = compare(scene, results, "reference").set_index("metric")
    gaps = [
        abs(table.loc[m, "value"] - table.loc[m, "reference_value"])
        / max(abs(table.loc[m, "value"]), abs(table.loc[m, "reference_value"]))
        for m in (f"peak{k + 1}_amplitude_rad" for k in range(FREE_PEAKS))
    ]
    assert table.loc["max_abs_theta_rad", "difference"] == 0.0  # the release angle: says nothing
    line = verdict(scene, results, "reference", {"housner": results["housner"]})
    assert f"the first {FREE_PEAKS} peaks after release within {100 * max(gaps):.1f} % of reference" in line
    assert max(gaps) > 0.01 and "says nothing" not in line and "less than the difference" in line
    same = {"housner": results["housner"], "reference": results["housner"]}
    line = verdict(scene, same, "reference", same)
    assert "within 0.0 %" in line and "says nothing" not in line and "agree to the step's accuracy" in line


def test_verdict_leaves_out_a_block_at_rest_in_every_solver():
    """The bi-block with its upper block released: the lower block only tilts (the DEM's springs,
    about 5e-4 rad; the exact solver's micro-uplift, 4e-5 rad), 0.1 % of its alpha. The relative
    difference of two such tilts (92.6 %) once was the verdict's number, while the rocking block
    agreed within 5 %: a block at rest in every solver is left out and named, a block that
    rocks is compared."""
    from rockyade.analysis.compare import _peaks, _relative, verdict
    from rockyade.scene import load_scene
    from rockyade.solvers import make_solver

    scene = load_scene(EXAMPLES / "biblock_free.toml")
    results = {n: make_solver(n).run(scene) for n in ("twoblock", "reference")}
    upper = _relative(_peaks(scene, results["twoblock"])["upper"], _peaks(scene, results["reference"])["upper"])
    line = verdict(scene, results, "reference")
    assert 0.001 < upper < 0.1
    assert f"within {100 * upper:.1f} % of reference (largest: twoblock, upper)" in line
    assert "(lower at rest in every solver, below 1 % of its alpha: not compared)" in line
    # a block that rocks in one solver only is compared: the lower block's tilt against itself x 100
    lifted = make_solver("twoblock").run(scene)
    lifted.frame["lower_theta_rad"] *= 100
    line = verdict(scene, {"twoblock": lifted, "reference": results["reference"]}, "reference")
    assert "largest: twoblock, lower" in line and "at rest" not in line


# ---------------------------------------------------------------------- real records


@needs_records("RSN6_IMPVALL.I_I-ELC180-hor1.AT2", "RSN77_SFERN_PUL164-hor1.AT2")
def test_real_records_housner_and_the_reference_dem_agree_on_a_slender_block(tmp_path):
    """Two PEER records (El Centro 1940, Pacoima Dam 1971) copied into a folder of their own:
    the collapse intensities of Housner and the reference DEM, paired by record, within 10 %."""
    import shutil

    from rockyade.assess import parse_measure, records_in_folder
    from rockyade.runner import Executor
    from rockyade.scene import load_scene
    from rockyade.studies.crosscheck import crosscheck_plan

    folder = tmp_path / "peer"
    folder.mkdir()
    for name in ("RSN6_IMPVALL.I_I-ELC180-hor1.AT2", "RSN77_SFERN_PUL164-hor1.AT2"):
        shutil.copy(external_records_dir() / name, folder / name)
    plan = crosscheck_plan(
        load_scene(EXAMPLES / "specimen1_record.toml"),
        records_in_folder(folder),
        parse_measure("pga"),
        ["housner", "reference"],
        dt_factors=(1.0,),
        resolution=0.05,
        executor=Executor("threads", 1),
        tail_s=2.0,
        progress=False,
    )
    summary = run(plan, tmp_path / "out")
    pair = summary.pairs[summary.pairs.kind == "solvers"].iloc[0]
    assert pair.records == 2
    assert 0.9 <= pair.median_ratio <= 1.1, pair.sentence


def test_figure_text_does_not_overlap(tmp_path):
    """Many rows with long labels and a wide range (as the paper's figure): no two texts of the
    figure (tick labels, axis label, legend) overlap."""
    from matplotlib.text import Text

    from rockyade.figures.paired_ratios import PairedRatios

    rows = []
    for k in range(1, 5):
        for kind, a, b in (("dt", "reference", "reference"), ("solvers", "housner", "reference")):
            rows.append(
                {
                    "scene": f"specimen {k}",
                    "kind": kind,
                    "solver_a": a,
                    "solver_b": b,
                    "dt_factor_a": 0.5,
                    "dt_factor_b": 1.0,
                    "records": 30,
                    "median_ratio": 1.0 + 0.02 * k,
                    "ratio_low": 0.8,
                    "ratio_high": 1.4,
                }
            )
    display = PairedRatios.from_pairs(pd.DataFrame(rows), "PGA")
    display.save(tmp_path / "f.png")
    fig = display.figure_
    fig.canvas.draw()  # the layout at the figure's own dpi (savefig draws at another)
    renderer = fig.canvas.get_renderer()
    texts = [t for t in fig.findobj(Text) if t.get_visible() and t.get_text().strip()]
    boxes = [t.get_window_extent(renderer) for t in texts]
    for i in range(len(boxes)):
        for j in range(i + 1, len(boxes)):
            assert not boxes[i].overlaps(boxes[j]), (texts[i].get_text(), texts[j].get_text())


def test_too_few_records_give_no_interval_and_no_verdict():
    """Two records cannot bound a median: no interval is quoted and no verdict given (as a
    fragility fit refuses fewer than 5 records); 5 to 9 records carry a warning."""
    two = pair_verdict("housner", "reference", median_interval([1.044, 1.091]), 0.05)
    assert two.verdict == "too few records" and "interval" in two.sentence and "nan" not in two.sentence
    one = pair_verdict("housner", "reference", median_interval([1.02]), 0.05)
    assert one.verdict == "too few records" and "nan" not in one.sentence
    six = pair_verdict("a", "b", median_interval([1.0, 1.01, 0.99, 1.02, 0.98, 1.0]), 0.05)
    assert six.verdict == "agree" and "rough interval" in six.sentence


def test_resume_of_a_complete_study_is_refused_and_leaves_it_alone(complete):
    """--resume over a finished cross-check has nothing to finish: one line naming --resume,
    and the complete set untouched (before, it ran every run again)."""
    out, _ = complete
    before = {p: p.stat().st_mtime_ns for p in out.rglob("*") if p.is_file()}
    with pytest.raises(InputError, match="nothing to resume"):
        run(None, out, resume=True)  # the refusal comes before the plan is used
    assert {p: p.stat().st_mtime_ns for p in out.rglob("*") if p.is_file()} == before


# ---------------------------------------------------------------------- make run's part


def test_paper_part_runs_siconos_on_a_subset_it_can_run():
    """``make run``'s cross-check has YADE and Siconos subsets beside the four specimens; Siconos's
    uses the paper's calibration, since it cannot reach specimen 1's matched mu (refused)."""
    from rockyade.siconos.backend import siconos_available
    from rockyade.siconos.calibration import check_target_mu
    from rockyade.solvers import make_solver
    from rockyade.studies import paper_crosscheck as pc

    todo, left_out = pc.jobs(use_yade=False)
    assert [j.solvers for j in todo][:4] == [("housner", "reference")] * 4
    assert any("YADE" in why for why in left_out)  # said, not silently dropped
    siconos = [j for j in todo if "siconos" in j.solvers]
    if not siconos_available():
        assert not siconos and any("Siconos" in why for why in left_out)
        return
    (job,) = siconos
    assert job.solvers == ("reference", "siconos") and job.records >= 5 and job.calibration == "paper"
    solver = make_solver("siconos")
    matched = pc.specimen_scene(job.specimen)
    with pytest.raises(InputError, match="cannot reach"):
        check_target_mu(matched, solver.model(matched))
    chosen = pc.specimen_scene(job.specimen, job.calibration)
    check_target_mu(chosen, solver.model(chosen))
    assert [j.solvers for j in pc.jobs(use_yade=True)[0] if "yade" in j.solvers] == [("reference", "yade")]


# ---------------------------------------------------------------------- refused up front


@pytest.mark.parametrize(
    ("scene", "solvers", "words"),
    [
        # Specimen 1's matched mu 0.936 is beyond Siconos's reach (before, every Housner run ran,
        # every Siconos run failed and a set with an "inconclusive" verdict replaced --out)
        ("specimen1_record.toml", "housner,siconos", ("contact.calibration", "siconos")),
        # Housner's solution is for one block (before, every reference run ran, every Housner run
        # failed with this refusal, and the study ended with exit 1)
        ("biblock_geometry.toml", "housner,reference", ("blocks:", "housner solver takes one block", "twoblock")),
    ],
)
def test_a_scene_a_solver_refuses_is_refused_before_any_run(scene, solvers, words, records, tmp_path, capsys):
    """One line naming the field and the solver, exit 2, before any run and with no --out written."""
    code = cli(
        "crosscheck",
        str(EXAMPLES / scene),
        "--records",
        str(records),
        "--solvers",
        solvers,
        "--levels",
        "0.3,0.6",
        "--resolution",
        "0.5",
        "--dt-factors",
        "1",
        "--out",
        str(tmp_path / "o"),
        "--quiet",
    )
    captured = capsys.readouterr()
    err = captured.err.strip().splitlines()
    assert code == 2 and len(err) == 1 and all(w in err[0] for w in words), err
    assert "cost:" not in captured.out and not (tmp_path / "o").exists()


def test_runs_that_failed_are_said_and_a_pair_whose_solver_always_failed_says_so(plan):
    """Outcomes where the reference DEM failed every run: the pair's verdict says so with the
    reason (not "inconclusive"), its searches say "every run failed" (not "no runs") and
    index.md counts the failures per solver with their first reasons."""
    from rockyade.studies.crosscheck import Outcomes
    from rockyade.studies.crosscheck.reporting import index_text, summarise

    outcomes = Outcomes()
    low, high = plan.scan_si[0], plan.scan_si[1]
    for f in plan.dt_factors:
        for i in plan.records_of("housner"):
            outcomes.add(("housner", f, i), low, {"status": "completed", "run": "a"}, False)
            outcomes.add(("housner", f, i), high, {"status": "overturned", "run": "b"}, True)
            for level in (low, high):
                row = {"status": "failed", "failure_reason": "InputError: contact.calibration: out of reach"}
                outcomes.add(("reference", f, i), level, row, None)
    summary = summarise(plan, outcomes, partial=False)
    assert all("reference failed every run (4 of 4; first reason: InputError" in v for v in summary.verdicts)
    assert "inconclusive" not in " ".join(summary.verdicts)
    mine = summary.collapse[summary.collapse.solver == "reference"]
    assert set(mine.status) == {ALL_FAILED} and (mine.failed_runs == mine.runs).all()
    index = index_text(plan, summary, 1.0)
    assert "## Failed runs" in index and "8 of 16 runs failed" in index
    assert "- reference at dt x 1: 4 of 4 runs failed (every run); first reasons: InputError" in index
    assert "housner at dt x" not in index.split("## Failed runs")[1].split("##")[0]


def long_records(folder: Path, duration_s: float = 30.0) -> Path:
    """Two records of ``duration_s`` (a sine pulse, then calm), m/s^2."""
    folder.mkdir(parents=True, exist_ok=True)
    t = np.arange(0.0, duration_s + 1e-9, 0.01)
    for k, period in enumerate((0.45, 0.8)):
        a = 3.0 * np.sin(2 * np.pi * t / period) * np.exp(-(((t - 1.2) / 0.6) ** 2))
        lines = [f"# long record {k + 1}", "t_s,accel_m_s2"] + [f"{x:.4f},{y:.6g}" for x, y in zip(t, a, strict=True)]
        (folder / f"long{k + 1}.csv").write_text("\n".join(lines) + "\n")
    return folder


def test_a_study_expected_to_take_hours_is_refused_naming_allow_large(tmp_path, capsys):
    """dt x 0.001 makes Siconos's runs of 30 s records hours long (about 115 million steps of
    60 us): refused before any run, on the run's estimated time (one run) or the study's
    expected time (all of them), naming --allow-large."""
    from rockyade.runner.cost_limits import MAX_STUDY_S, check_study_time

    scene = tmp_path / "paper.toml"
    text = (EXAMPLES / "specimen1_record.toml").read_text().replace('"matched"', '"paper"')
    scene.write_text(text.replace("records/", str(EXAMPLES / "records") + "/"))
    records = long_records(tmp_path / "long")
    argv = ["crosscheck", str(scene), "--records", str(records), "--solvers", "housner,siconos"]
    argv += ["--levels", "0.3,0.6", "--resolution", "0.5", "--out", str(tmp_path / "o"), "--quiet"]
    assert cli(*argv, "--dt-factors", "1,0.001") == 2
    captured = capsys.readouterr()
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and "--allow-large" in err[0] and "siconos" in err[0], err
    assert "round 1" not in captured.out and not (tmp_path / "o").exists()
    with pytest.raises(InputError, match="expected to take about 9 h on 2 worker"):
        check_study_time(9 * 3600.0, "the cross-check", 2)
    check_study_time(MAX_STUDY_S, "the cross-check", 2)  # at the limit: runs


def test_compare_prints_its_cost_and_refuses_hours(tmp_path, capsys):
    """``rockyade compare --dt-factor 0.001`` with Siconos on 30 s of free rocking (about 115
    million steps: hours): refused before any run (exit 2, one line naming --allow-large);
    before, it printed no cost and ran for minutes."""
    scene = tmp_path / "long.toml"
    scene.write_text((EXAMPLES / "specimen1_free.toml").read_text().replace("duration_s = 4.0", "duration_s = 30.0"))
    assert "duration_s = 30.0" in scene.read_text()
    code = cli(
        "compare",
        str(scene),
        "--solvers",
        "housner,siconos",
        "--dt-factor",
        "0.001",
        "--out",
        str(tmp_path / "c"),
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "--allow-large" in err[0] and "siconos" in err[0], err
    assert not (tmp_path / "c").exists()


def test_records_folder_given_as_a_link_is_named_as_given(records, tmp_path):
    """--records as a link to a folder: the console and index.md name the link, not its
    target's folder; one record is "1 record file"."""
    from rockyade.assess import records_in_folder

    link = tmp_path / "my_records"
    link.symlink_to(records)
    motions = records_in_folder(link)
    assert motions.describe() == f"2 record files of {link}" and str(records) not in motions.describe()
    assert motions == records_in_folder(records)  # the same records, whatever the folder's name
    one = write_records(tmp_path / "one", count=1)
    assert records_in_folder(one).describe() == f"1 record file of {one}"


def test_below_min_records_no_interval_is_shown_anywhere_and_digits_follow_the_resolution(plan, tmp_path):
    """Two records (fewer than MIN_RECORDS): the verdict refuses an interval, and so do
    pairs.csv, the convergence lines, the paired-ratios table and the figure, each saying why;
    the fragility rows say why they have no numbers; a 10 % resolution gives 2 decimals."""
    from rockyade.analysis.crosscheck_statistics import MIN_RECORDS, ratio_decimals
    from rockyade.figures.paired_ratios import PairedRatios
    from rockyade.studies.crosscheck import Outcomes
    from rockyade.studies.crosscheck.reporting import index_text, summarise

    assert plan.motions.count < MIN_RECORDS and plan.resolution == 0.1
    assert (ratio_decimals(0.01), ratio_decimals(0.1), ratio_decimals(0.5)) == (3, 2, 1)
    outcomes = Outcomes()
    scan = sorted(plan.scan_si)
    for s, top in (("housner", 1), ("reference", 2)):
        for f in plan.dt_factors:
            for i in plan.records_of(s):
                for k, level in enumerate(scan):
                    outcomes.add((s, f, i), level, {"status": "completed"}, k >= top)
    summary = summarise(plan, outcomes, partial=False)
    assert (summary.pairs.records == 2).all()
    assert summary.pairs.ratio_low.isna().all() and summary.pairs.ratio_high.isna().all()
    index = index_text(plan, summary, 1.0)
    results = index.split("## Verdicts")[1].split("## Files")[0]
    assert not re.search(r"95 % interval [0-9]", results) and "no interval: 2 record(s), fewer than the 5" in results
    assert "none (2 < 5 records)" in index
    verdict = summary.verdicts[0]
    assert "housner / reference = 0.50 from 2 record(s)" in verdict, verdict
    fragility = index.split("## Fragility per solver")[1].split("##")[0]
    rows = [line for line in fragility.splitlines() if line.startswith("| housner") or line.startswith("| reference")]
    assert rows and all("not fitted" in row for row in rows), rows
    display = PairedRatios.from_pairs(summary.pairs)
    assert all("no interval" in label for label in display.labels)


def test_default_levels_start_at_the_alpha_the_solvers_run(records):
    """Specimen 1 declares alpha_rad = 0.235: the scan starts at tan(0.235) g, the uplift level
    of the block the solvers run (before: 0.2501 g from the nominal 0.25 x 1.0 m geometry's
    limit analysis); an assembly keeps the limit analysis' alpha0."""
    from rockyade.assess import parse_measure, records_in_folder
    from rockyade.constants import CODE_GRAVITY, G
    from rockyade.runner import Executor
    from rockyade.scene import load_scene
    from rockyade.studies.crosscheck import classical_static, crosscheck_plan

    scene = load_scene(EXAMPLES / "specimen1_record.toml")
    assert scene.blocks[0].classical().alpha_rad == 0.235
    cc = crosscheck_plan(
        scene,
        records_in_folder(records),
        parse_measure("pga"),
        ["housner", "reference"],
        dt_factors=(1.0,),
        executor=Executor("threads", 1),
        progress=False,
    )
    assert cc.scan_si[0] == pytest.approx(math.tan(0.235) * G)
    assert cc.scan_si[0] / CODE_GRAVITY == pytest.approx(0.2395, abs=1e-4)
    assert "classical alpha = 0.235 rad" in cc.stripes.levels_source
    assert classical_static(load_scene(EXAMPLES / "biblock_free.toml")) is None


# ---------------------------------------------------------------------- Ctrl-C, a full disk, failed runs


@pytest.fixture(scope="module")
def one_record_plan(tmp_path_factory):
    """One record, the solvers' own time step, a coarse bisection: a few rounds of a few runs."""
    return small_plan(write_records(tmp_path_factory.mktemp("one") / "records", count=1), dt_factors=(1.0,))


def test_a_ctrl_c_at_a_rounds_end_is_kept_for_the_next_round(one_record_plan, tmp_path, monkeypatch):
    """A single Ctrl-C after the last run of round 1 finished (delivered through the study's stop
    request, as the signal handler does): no round 2 starts; exit 130 with the partial summary and
    the --resume hint (it used to say "no new run starts", run rounds 2-6 and exit 0)."""
    import signal

    import rockyade.studies.crosscheck as cc

    real = cc.search.run_study
    rounds: list[int] = []

    def ctrl_c_at_the_end(tasks, *args, **kwargs):
        runs = real(tasks, *args, **kwargs)
        rounds.append(len(tasks))
        kwargs["stop"]._handler(signal.SIGINT, None)  # the first Ctrl-C, the round's runs all finished
        return runs

    monkeypatch.setattr(cc.search, "run_study", ctrl_c_at_the_end)
    out = tmp_path / "out"
    with pytest.raises(BatchInterruptedError) as info:
        run(one_record_plan, out)
    assert len(rounds) == 1 and info.value.resume_option == "--resume" and "--resume" in str(info.value)
    assert "PARTIAL" in (out / "partial" / "index.md").read_text() and not (out / "crosscheck.json").exists()
    assert json.loads((out / "partial" / "crosscheck.json").read_text())["partial"] is True
    monkeypatch.setattr(cc.search, "run_study", real)
    summary = run(one_record_plan, out, resume=True)
    data = json.loads((out / "crosscheck.json").read_text())
    assert summary.partial is False and data["runs_reused"] == rounds[0] and not (out / "partial").exists()


def test_a_ctrl_c_while_the_set_is_written_leaves_the_previous_set_and_a_partial_summary(
    one_record_plan, tmp_path, monkeypatch
):
    import rockyade.studies.crosscheck as cc

    out = tmp_path / "out"
    run(one_record_plan, out)
    before = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    real = cc.search.write_summary

    def ctrl_c_in_the_set(plan, summary, folder, *args, **kwargs):
        if folder.name.startswith(".set."):
            raise KeyboardInterrupt
        return real(plan, summary, folder, *args, **kwargs)

    monkeypatch.setattr(cc.search, "write_summary", ctrl_c_in_the_set)
    with pytest.raises(BatchInterruptedError, match="--resume"):
        run(one_record_plan, out)
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()} == before
    assert "PARTIAL" in (out / "partial" / "index.md").read_text() and not list(out.glob(".set.*"))


def test_a_full_disk_while_the_set_is_written_names_the_file(one_record_plan, tmp_path, monkeypatch):
    import errno
    import os

    from rockyade.errors import os_error_message

    real = os.fsync

    def full_in_the_set(fd: int) -> None:
        if "/.set." in os.readlink(f"/proc/self/fd/{fd}"):
            raise OSError(errno.ENOSPC, "No space left on device")
        real(fd)

    out = tmp_path / "out"
    monkeypatch.setattr(os, "fsync", full_in_the_set)
    with pytest.raises(OSError) as info:
        run(one_record_plan, out)
    said = os_error_message(info.value)
    assert "disk full" in said and said.startswith(str(out / "")) and Path(info.value.filename).name in RESULT_NAMES
    assert not list(out.glob(".set.*")) and (out / "partial" / "study.json").is_file()  # --resume writes it


RESULT_NAMES = (".names", "collapse_intensities.csv", "pairs.csv", "runs.csv", "crosscheck.json", "crosscheck.png",
                "index.md")  # fmt: skip


def test_failed_runs_are_run_again_on_resume_and_their_searches_go_on(one_record_plan, tmp_path, monkeypatch):
    """Runs that failed (a worker killed, say) end their searches at their bracket so far; the set
    says so and keeps the journal, and --resume runs them again and finishes the searches (it used
    to say "nothing is unfinished", the coarse bracket kept)."""
    import rockyade.batch.running as running

    real = running.answered_row
    failing = {"n": 0}

    def some_fail(task, result, row):
        if task.solver.name == "reference" and failing["n"] < 2:
            failing["n"] += 1
            return row.failed("the worker process died (killed, or out of memory)")
        return real(task, result, row)

    monkeypatch.setattr(running, "answered_row", some_fail)
    out = tmp_path / "out"
    first = run(one_record_plan, out)
    assert failing["n"] == 2 and first.runs["collapsed"].isna().sum() == 2
    assert (out / "crosscheck.json").is_file() and (out / "partial" / "study.json").is_file()
    monkeypatch.setattr(running, "answered_row", real)
    again = run(one_record_plan, out, resume=True)
    assert again.runs["collapsed"].notna().all() and not (out / "partial").exists()
    data = json.loads((out / "crosscheck.json").read_text())
    assert data["runs_made"] >= 2 and data["runs_reused"] == len(first.runs) - 2
    clean = run(one_record_plan, tmp_path / "clean")  # the searches as if nothing had failed
    pd.testing.assert_frame_equal(again.collapse, clean.collapse)
