"""Start-up of the command line: heavy libraries are imported where they are used.

``rockyade --help`` (and any command's ``--help``) and ``import rockyade.scene`` must not
import scipy's submodules, pandas, matplotlib or dask (issue "Studies at scale", item 6):
each costs 0.3-2 s on a loaded machine, for commands that never use them.
The checks run in a fresh interpreter, so that nothing imported by other tests counts.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

HEAVY = ("scipy.", "pandas", "matplotlib", "dask", "distributed", "pyarrow")
PRIVATE = ("scipy._", "scipy.version")
#: The solvers' compiler: the parser never needs it; scenes do (the ground-motion lookup is compiled).
COMPILER = "numba"


def _imported_after(code: str) -> list[str]:
    """The heavy modules in ``sys.modules`` after running ``code`` in a fresh interpreter."""
    probe = code + "\nimport json, sys\nprint(json.dumps(sorted(sys.modules)))"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True, timeout=120)
    modules = json.loads(out.stdout.strip().splitlines()[-1])
    # numba imports scipy's package and its private helpers (tens of ms); its public submodules
    # (integrate, signal, linalg, stats, ...) are the heavy ones.
    return [m for m in modules if (m.startswith(HEAVY) and not m.startswith(PRIVATE)) or m == COMPILER]


def test_help_imports_no_heavy_library() -> None:
    code = (
        "import contextlib, io\n"
        "from rockyade.cli import build_parser\n"
        "parser = build_parser()\n"
        "with contextlib.suppress(SystemExit), contextlib.redirect_stdout(io.StringIO()):\n"
        "    parser.parse_args(['--help'])\n"
    )
    heavy = _imported_after(code)
    assert heavy == [], f"rockyade --help imports {heavy[:8]}"


@pytest.mark.parametrize("module", ["rockyade.scene", "rockyade.motion", "rockyade.result"])
def test_scene_and_motion_import_no_scipy_or_pandas(module: str) -> None:
    code = f"import {module}\n"
    if module == "rockyade.scene":
        code += "rockyade.scene.load_scene\n"  # the loader (lazy in rockyade.scene) too
    heavy = [m for m in _imported_after(code) if m != COMPILER]
    assert heavy == [], f"import {module} imports {heavy[:8]}"


@pytest.mark.slow
def test_the_dem_model_imports_scipy_spatial_only_for_an_alpha_override() -> None:
    # scipy.spatial (0.2-1 s) serves only a block whose base is replaced by its alpha (ConvexHull)
    heavy = _imported_after("import rockyade.calibration.model_stage\nimport rockyade.solvers.reference\n")
    assert not [m for m in heavy if m.startswith("scipy.spatial")], heavy[:8]
    code = (
        "from rockyade.blocks.geometry import Block\n"
        "from rockyade.dem.model_from_scene import contact_polygon\n"
        "contact_polygon(Block.rectangle(0.25, 1.0, 0.754, mass_kg=503), 0.2)\n"
    )
    assert any(m.startswith("scipy.spatial") for m in _imported_after(code))


def test_the_cost_estimate_and_the_run_build_one_model(monkeypatch: pytest.MonkeyPatch) -> None:
    # rockyade run estimates the cost (the model's time step), then runs: one model build
    import rockyade.calibration.model_stage as model_module
    from rockyade.scene import scene_from_dict
    from rockyade.solvers import make_solver

    builds = []
    build = model_module._calibrated_model
    monkeypatch.setattr(model_module, "_calibrated_model", lambda *a: builds.append(a) or build(*a))
    scene = scene_from_dict(
        {
            "duration_s": 0.05,
            "sample_dt_s": 0.001,
            "blocks": [{"name": "b", "width_m": 0.25, "height_m": 1.0, "thickness_m": 0.754, "mass_kg": 503}],
            "contact": {"calibration": "paper"},
            "motion": {"type": "free", "theta0_rad": 0.05},
        }
    )
    solver = make_solver("reference")
    estimate = solver.estimate_cost(scene)
    result = solver.run(scene)
    assert len(builds) == 1
    assert result.ok and estimate.time_step_s == pytest.approx(result.meta.dt_s, rel=1e-12)
