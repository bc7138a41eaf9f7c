"""Compilation of the solvers' numba code: ahead of any run (``make setup`` runs
``python -m rockyade.solvers.compile_cache``), and when a run finds numba's cache cold it says
so on stderr and its cost estimate counts it (issue 34, section 2).

A cold cache is made by pointing ``NUMBA_CACHE_DIR`` at an empty folder in a fresh
interpreter (numba then reads and writes its cache there only).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from rockyade.scene import scene_from_dict
from rockyade.solvers import make_solver
from rockyade.solvers.compile_cache import compile_all, main

from .conftest import free_scene_dict

COMPILING = "compiling the solver (first run only)"

#: Estimate, run and estimate again in one process: the lines of stderr are the test's.
_PROBE = """
import json, sys
from rockyade.scene import scene_from_dict
from rockyade.solvers import make_solver
scene = scene_from_dict(json.loads(sys.argv[1]))
solver = make_solver("housner")
before = solver.estimate_cost(scene)
status = solver.run(scene).meta.status
after = solver.estimate_cost(scene)
print(json.dumps({"before": before.compile_s, "described": before.describe(), "after": after.compile_s,
                  "status": status, "again": solver.run(scene).meta.status}))
"""


def _probe(cache: Path) -> tuple[dict, str]:
    """The probe's answer and its stderr, numba's cache in ``cache``."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    scene = json.dumps(free_scene_dict(duration=0.2))
    out = subprocess.run(
        [sys.executable, "-c", _PROBE, scene], capture_output=True, text=True, env=env, timeout=900, check=True
    )
    return json.loads(out.stdout), out.stderr


@pytest.mark.slow
def test_a_cold_cache_is_said_once_and_counted_in_the_estimate(tmp_path: Path) -> None:
    answer, stderr = _probe(tmp_path)
    assert stderr.count(COMPILING) == 1, stderr  # the first run says it, the second (loaded) does not
    assert "housner" in stderr
    assert answer["status"] == answer["again"] == "completed"
    assert answer["before"] == make_solver("housner").COMPILE_S > 0  # type: ignore[attr-defined]
    assert "compiling the solver (first run only)" in answer["described"]
    assert answer["after"] == 0.0  # compiled in this process: nothing left to compile

    # the next process finds the code in the cache: silent, nothing to count
    answer, stderr = _probe(tmp_path)
    assert COMPILING not in stderr
    assert answer["before"] == 0.0


def test_compiling_ahead_leaves_nothing_to_compile(capsys) -> None:
    compile_all()  # the suite's own cache (make setup compiled it; else this compiles it once)
    capsys.readouterr()
    done = compile_all()
    assert {c.name for c in done} == {"housner", "reference", "twoblock", "spectra"}
    assert all(c.was_cached for c in done)
    said = capsys.readouterr().out
    assert "compiling" not in said and said.count("in the cache, loaded") == 4
    assert main(["--quiet", "--workers", "2"]) == 0  # make setup's call: nothing missing, no worker started
    assert capsys.readouterr().out == ""  # quiet: only what is compiled, and nothing is

    scene = scene_from_dict(free_scene_dict(duration=0.2))
    for name in ("housner", "reference", "twoblock"):
        solver = make_solver(name)
        assert solver.compiled_cached(scene)  # type: ignore[attr-defined]
    estimate = make_solver("reference").estimate_cost(scene)
    assert estimate.compile_s == 0.0 and "compiling" not in estimate.describe()
