"""``benchmarks/bench_siconos.py --quick``: every part runs on small scenes and prints its
table (YADE, the reference DEM and Siconos side by side, Siconos's ratio to YADE and its cost
per 25 s record, the convergence of its step and tolerance), so that the benchmark cannot
rot. Its numbers check the script, not the targets (docs/siconos.md has those). Skipped where
YADE or Siconos is absent (``make test`` requires both)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from .benchrun import run_quick
from .processes import require_siconos, require_yade

BENCH = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_siconos.py"


@pytest.mark.yade
@pytest.mark.siconos
def test_the_siconos_benchmark_runs_every_part_in_its_quick_mode(capsys, monkeypatch):
    require_yade()
    require_siconos()
    out = run_quick(BENCH, monkeypatch, capsys, "wall", "arch", "biblock", "block", "costs", "convergence")
    headings = ("wall of 5 blocks", "arch of 6 voussoirs", "bi-block under the EC8 record", "single block")
    for heading in (*headings, "measured against estimate_cost"):
        assert heading in out, heading
    ratios = [float(x) for x in re.findall(r"\(\s*([0-9.]+) x YADE\)", out)]
    assert len(ratios) >= 5 and all(r > 0 for r in ratios), out
    assert len(re.findall(r"[0-9.]+ min per 25 s record", out)) >= 5, out
    assert "failed" not in out, out
    assert len(re.findall(r"estimate +[0-9.e+-]+ s \( *[0-9.]+x\)", out)) == 12, out
    assert re.search(r"dt / 2 against the default: wall peak [-+][0-9.]+ %", out), out
    assert re.search(r"tolerance / 2 against the default: wall peak [-+][0-9.]+ %", out), out
