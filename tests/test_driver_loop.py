"""The loop every worker driver runs (rockyade.io.driver_loop), without an engine: it imports
only the standard library (the drivers load it by path in their engine's Python), both drivers
load it and keep no loop of their own, and over a real socket pair with rockyade's side
(rockyade.io.warm_program) it runs jobs, writes the one output dialect, and reports a job
that raised or an output it could not write."""

from __future__ import annotations

import ast
import json
import sys
from pathlib import Path

import numpy as np

import rockyade
from rockyade.dem.worker_output import WorkerOutput
from rockyade.io import driver_loop, warm_program

from .processes import fake_program

PACKAGE = Path(rockyade.__file__).parent
LOOP = Path(driver_loop.__file__)


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text())
    names = {a.name.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
    return names | {n.module.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module}


def test_the_loop_imports_only_the_standard_library_and_both_drivers_use_it():
    assert _imports(LOOP) <= set(sys.stdlib_module_names), _imports(LOOP) - set(sys.stdlib_module_names)
    for engine in ("yade", "siconos"):
        driver = PACKAGE / engine / "driver.py"
        assert "rockyade" not in _imports(driver)
        text = driver.read_text()
        assert '"io", "driver_loop.py"' in text and "LOOP.serve(" in text and "LOOP.output_meta(" in text
        tree = ast.parse(text)
        own = {n.name for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
        assert not own & {"_send", "_exit", "OutputError", "_write_replacing"}, own
    assert (PACKAGE / "yade" / "driver.py").parent.parent / "io" / "driver_loop.py" == LOOP


def _run(tmp_path: Path, job: dict, out: Path) -> tuple[str | None, str]:
    scene = tmp_path / f"{job['name']}.json"
    scene.write_text(json.dumps(job))
    log = tmp_path / f"{job['name']}.log"
    reason = warm_program.run_scene(fake_program(), scene, out, log, 60.0, warm=True)
    return reason, log.read_text()


def test_a_job_runs_and_writes_the_one_dialect_then_failures_are_reported(tmp_path):
    try:
        out = tmp_path / "a.npz"
        reason, log = _run(tmp_path, {"name": "a"}, out)
        assert reason is None and "running a" in log
        with np.load(out, allow_pickle=False) as data:
            meta = json.loads(str(data["meta"]))
        assert {"status", "n_filled", "steps", "version", "wall_time_s", "complete", "process_cpu_s"} <= set(meta)
        typed = WorkerOutput.from_dict(meta)
        assert typed.steps == 7 and typed.version == "fake 1.0" and typed.n_filled == 2 and typed.complete
        assert typed.max_residual == 1e-9  # the engine's own key, read under its name
        assert not (tmp_path / "a.npz.part").exists()

        reason, log = _run(tmp_path, {"name": "b"}, tmp_path / "missing" / "b.npz")  # the same warm worker
        assert reason is not None and "Fake could not write its output" in reason and "b.npz:" in reason

        reason, log = _run(tmp_path, {"name": "c", "raise": True}, tmp_path / "c.npz")
        assert reason == "Fake exited with code 1" and "RuntimeError: the scene raised" in log
        reason, log = _run(tmp_path, {"name": "d"}, tmp_path / "d.npz")  # a fresh worker takes the next
        assert reason is None and "running d" in log
    finally:
        warm_program.close_workers("Fake")
