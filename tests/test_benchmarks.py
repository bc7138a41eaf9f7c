"""Every script of ``benchmarks/`` runs in its quick mode and prints its figures, so that none
can rot (``make bench`` crashed on a signature that had changed under it). The numbers of a
quick run mean nothing; what is checked is that the script ends cleanly and prints the lines
that carry its figures.

Scripts run elsewhere in their quick mode are named in :data:`RUN_ELSEWHERE` with the test
that runs them; a new script that is in neither list fails
:func:`test_every_benchmark_script_is_run_by_a_test`."""

from __future__ import annotations

import os
import re
import runpy
import sys
from pathlib import Path

import pytest

from .processes import require_siconos, require_yade

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"

#: Script -> (arguments of its quick run, patterns its output must hold, what it needs).
QUICK: dict[str, tuple[list[str], list[str], str]] = {
    "bench_batch.py": (["--quick"], [r"collapse batch, 6 reference-DEM runs of 25 s: .* runs/s"], ""),
    "bench_groups.py": (
        ["--quick"],
        [r"fragility, housner +\d+", r"overturning scans, reference", r"uncertainty, reference", r"ms CPU per task"],
        "",
    ),
    "bench_housner.py": (["--quick"], [r"housner free rocking, 2 s simulated", r"housner under a 2 s record"], ""),
    "bench_identify.py": (["--quick"], [r"white noise", r"AR\(1\) noise"], ""),
    "bench_reference.py": (["--quick"], [r"ns/step", r"reference DEM batch, 10 x 10 s harmonic variants"], ""),
    "bench_scale.py": (["--quick"], [r"^pulse +10 "], ""),
    "bench_startup.py": (["--quick"], [r"params --help +[0-9.]+", r"run --solver reference \(1 s\)"], ""),
    "bench_synthetic.py": (["--quick"], [r"synthetic suite, 3 EC8 Type 2 / D records of 20 s"], ""),
    "bench_targets.py": (
        ["--quick"],
        [r"kernel: single-body path / hand-written floor", r"overhead of a 25 s batch run", r"parallel efficiency"],
        "",
    ),
    "bench_uncertainty.py": (
        ["--quick", "--out", "bench_uncertainty"],
        [r"sensitivity of specimens 1-4", r"fragility convergence", r"wrote bench_uncertainty in"],
        "",
    ),
    "bench_yade.py": (["--quick"], [r"wall of \d+ blocks", r"YADE, 2 runs of 0.5 s", r"cold and warm"], "yade"),
    "bench_siconos_mu.py": (["--quick"], [r"^1\. ", r"^2\. ", r"^3\. "], "siconos"),
    "specimen3_gap.py": (["--quick", "--out", "gap"], [r"\[base\] housner dt x 1 / reference dt x 1: "], ""),
    # the masonry scenes' costs, on the bi-block with the exact solver and Siconos (its child's CPU counted)
    "crosscheck_costs.py": (
        ["--quick", "--scenes", "biblock-geometry", "--solvers", "twoblock,siconos"],
        [r"^\| biblock-geometry \| twoblock \| [0-9.]+ \|", r"^\| biblock-geometry \| siconos \| [0-9.]+ \|"],
        "siconos",
    ),
    # the cross-check suite's smallest run: one specimen, two records, one step, coarse bisection
    "crosscheck_suite.py": (
        ["--scenes", "1", "--count", "2", "--dt-factors", "1", "--resolution", "0.1", "--out", "xc"],
        [r"\| 1 \| housner / reference \| 1 \| 2 \|"],
        "",
    ),
}
#: Scripts whose quick mode another test runs (script -> that test).
RUN_ELSEWHERE = {
    "bench_siconos.py": "tests/test_bench_siconos.py",
    "bench_limit.py": "tests/test_limit_large.py::test_the_benchmark_runs_in_its_quick_mode",
    "bench_twoblock.py": (
        "tests/test_twoblock.py::test_benchmark_quick_mode_runs_and_finds_the_events_independent_of_sampling"
    ),
}
#: Not benchmarks: modules the others import, and the runner of them all.
HELPERS = {"floor.py", "quick_option.py", "run_all.py", "scratch.py"}


def test_every_benchmark_script_is_run_by_a_test():
    scripts = {p.name for p in BENCHMARKS.glob("*.py")}
    assert scripts - HELPERS == set(QUICK) | set(RUN_ELSEWHERE)
    root = BENCHMARKS.parent
    for test in RUN_ELSEWHERE.values():
        path, _, name = test.partition("::")
        assert (root / path).is_file(), test
        assert not name or f"def {name}(" in (root / path).read_text(), test


@pytest.mark.slow  # about 1.5 min of CPU over all the scripts (the machine's load decides the wall time)
@pytest.mark.parametrize(
    "script",
    [
        pytest.param(name, marks=[getattr(pytest.mark, needs)] if needs else [])
        for name, (_, _, needs) in sorted(QUICK.items())
    ],
)
def test_benchmark_runs_in_its_quick_mode(script, tmp_path, monkeypatch, capfd):
    """The script runs as ``make bench-all`` runs it (``benchmarks/run_all.py``: ``runpy`` in one
    process, its own ``sys.argv``), here in this test's process: a process per script paid
    some 2.5 s of CPU in imports and numba's cache before it did anything. As from ``python
    benchmarks/X.py``, its folder leads ``sys.path``; what it changes in ``os.environ`` and
    ``sys.path`` is put back. The output of its child processes is captured too (``capfd``)."""
    args, patterns, needs = QUICK[script]
    if needs == "yade":
        require_yade()
    if needs == "siconos":
        require_siconos()
    (tmp_path / "examples").symlink_to(BENCHMARKS.parent / "examples")  # as from a checkout, relative paths
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "argv", [str(BENCHMARKS / script), *args])
    monkeypatch.setattr(sys, "path", [str(BENCHMARKS), *sys.path])
    environ = dict(os.environ)  # bench_synthetic points ROCKYADE_CACHE elsewhere
    try:
        runpy.run_path(str(BENCHMARKS / script), run_name="__main__")
    except SystemExit as exc:
        assert exc.code in (None, 0), f"{script} exited {exc.code}\n{capfd.readouterr().err[-3000:]}"
    finally:
        for key in set(os.environ) - set(environ):
            del os.environ[key]
        os.environ.update(environ)
    out, err = capfd.readouterr()
    for pattern in patterns:
        assert re.search(pattern, out, re.M), f"{script}: no line matches {pattern!r}\n{out[-3000:]}"
    assert "Traceback" not in err, err[-3000:]


#: An option read from ``sys.argv`` by hand: a flag looked up in it, a slice compared, a loop over it.
BY_HAND = r"\"-[\w-]+\" in sys\.argv|sys\.argv\[\d+:\d+\]|for \w+ in sys\.argv"


def _exit_of(script: str, args: list[str], monkeypatch, capsys) -> tuple[object, str, str]:
    """The exit code, standard output and standard error of ``script`` run with ``args`` as
    ``python script ARGS`` would run it, in this process (``runpy``, as
    :func:`test_benchmark_runs_in_its_quick_mode`); it must end in ``SystemExit``."""
    with monkeypatch.context() as patch:
        patch.setattr(sys, "argv", [script, *args])
        patch.setattr(sys, "path", [str(BENCHMARKS), *sys.path])
        with pytest.raises(SystemExit) as ended:
            runpy.run_path(script, run_name="__main__")
    out, err = capsys.readouterr()
    return ended.value.code, out, err


def test_every_benchmark_takes_its_options_through_argparse(monkeypatch, capsys):
    """No script reads ``sys.argv`` by hand (``--help`` then ran the whole benchmark, minutes,
    and an unknown option was ignored): each parses its options (``quick_option.py`` or its own
    ``argparse``), so ``--help`` prints the usage and an unknown option exits 2. Run in this
    process: what is checked is the script's parsing, not a process (one cost some 0.7 s of
    CPU in imports)."""
    by_hand = [
        p.name for p in sorted(BENCHMARKS.glob("*.py")) if p.name != "run_all.py" and re.search(BY_HAND, p.read_text())
    ]
    assert by_hand == []
    script = str(BENCHMARKS / "bench_housner.py")
    code, out, _ = _exit_of(script, ["--help"], monkeypatch, capsys)
    assert code == 0 and out.startswith("usage:") and "--quick" in out
    code, _, err = _exit_of(script, ["--qiuck"], monkeypatch, capsys)
    assert code == 2 and "unrecognized arguments: --qiuck" in err
