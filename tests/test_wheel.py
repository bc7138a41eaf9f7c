"""The wheel works outside the checkout: built from a copy of the sources, installed into a
fresh virtual environment (no system site-packages, no editable install), and run from
another folder with relative paths.

The fresh environment holds the wheel and exactly the distributions its metadata requires,
followed from requirement to requirement (:func:`_link_requirements`): they are linked from
the environment running the tests, each checked against the version the requirement asks
for, rather than unpacked from pip's cache (some 500 MB written and byte-compiled again, most
of the test's cost). A module the package imports but does not require is absent there, as in
a user's environment. The build itself is pip's, isolated, with the setuptools that
pyproject.toml asks for (needs pip's index or its cache for it)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from importlib import metadata
from pathlib import Path

import pytest
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

from rockyade.yade import backend as yade_backend

from .conftest import EXAMPLES, ROOT

pytestmark = [pytest.mark.slow, pytest.mark.yade]

SKIP = shutil.ignore_patterns(
    ".venv",
    ".git",
    "reports",
    "build",
    "dist",
    "*.egg-info",
    "__pycache__",
    ".pytest_cache",
    ".ruff_cache",
    ".hypothesis",
    "compare",
    "gallery",
)


def _run(args: list[str], cwd: Path, timeout: float = 600, **extra_env: str) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTHON", "VIRTUAL_ENV"))} | extra_env
    proc = subprocess.run(args, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    assert proc.returncode == 0, f"{' '.join(args)}\n{proc.stdout[-2000:]}\n{proc.stderr[-3000:]}"
    return proc


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> Path:
    """A fresh venv with the wheel of this checkout installed; returns its bin folder."""
    tmp = tmp_path_factory.mktemp("wheel")
    src = tmp / "src"
    shutil.copytree(ROOT, src, ignore=SKIP)
    build = _run([sys.executable, "-m", "pip", "wheel", str(src), "--no-deps", "-v", "-w", str(tmp / "dist")], tmp)
    (tmp / "build.log").write_text(build.stdout + build.stderr)
    [wheel] = (tmp / "dist").glob("rockyade-*.whl")
    # A venv without pip of its own (ensurepip took some 6 s of CPU), filled by this pip through
    # --python; the wheel alone (--no-deps, --no-compile), its requirements linked beside it
    _run([sys.executable, "-m", "venv", "--without-pip", str(tmp / "venv")], tmp)
    bin_dir = tmp / "venv" / "bin"
    pip = [sys.executable, "-m", "pip", "--python", str(bin_dir / "python"), "install", "--quiet", "--no-compile"]
    _run([*pip, "--no-deps", "--disable-pip-version-check", str(wheel)], tmp)
    [site] = (tmp / "venv" / "lib").glob("python3*/site-packages")
    [info] = site.glob("rockyade-*.dist-info")
    linked = _link_requirements(metadata.PathDistribution(info).requires or [], site)
    assert {"numpy", "scipy", "pandas", "matplotlib", "numba", "highspy"} <= linked
    return bin_dir


def _link_requirements(requirements: list[str], site: Path) -> set[str]:
    """Link into ``site`` every distribution that ``requirements`` (a wheel's ``Requires-Dist``)
    need, and theirs in turn, from this environment: each entry of ``site-packages`` that a
    distribution's files name (its packages, modules and ``.dist-info``). A requirement of an
    extra counts only for the extras asked for; each installed version must satisfy the
    specifier (else the test fails: this environment is not what the wheel asks for). Returns
    the canonical names linked."""
    linked: set[str] = set()
    todo = [(Requirement(text), ("",)) for text in requirements]
    while todo:
        requirement, extras = todo.pop()
        if requirement.marker is not None and not any(requirement.marker.evaluate({"extra": e}) for e in extras):
            continue
        dist = metadata.distribution(requirement.name)
        assert requirement.specifier.contains(dist.version, prereleases=True), (str(requirement), dist.version)
        name = canonicalize_name(dist.metadata["Name"])
        if name in linked and not requirement.extras:
            continue
        linked.add(name)
        todo += [(Requirement(text), ("", *requirement.extras)) for text in dist.requires or []]
        for top in {f.parts[0] for f in dist.files or []} - {"..", "__pycache__"}:
            if not (site / top).exists():
                (site / top).symlink_to(Path(str(dist.locate_file(top))))
    return linked


def test_building_the_wheel_prints_no_packaging_warning(installed):
    """Every folder of examples/ is declared (setup.py), so setuptools has nothing to warn about
    (it printed 'Package rockyade.examples.assemblies is absent from the packages configuration'
    for each of them, some 270 lines at set-up)."""
    log = (installed.parent.parent / "build.log").read_text()
    assert "absent from the `packages` configuration" not in log
    assert "BuildBackendWarning" not in log and "SetuptoolsDeprecationWarning" not in log


#: Run by the installed Python in the work folder: where ``rockyade`` is imported from, the files
#: its metadata lists, and commands through ``rockyade.cli.main`` as the console script calls it
#: (each its own output, its exit code, its working folder); prints them as one JSON object.
#: One process for the commands that only print or run Housner's solver (a process each paid
#: the interpreter and the imports again).
COMMANDS = """
import contextlib, io, json, os, sys
from importlib.metadata import files

import rockyade
from rockyade.cli import main


def call(*argv, cwd="."):
    out, here = io.StringIO(), os.getcwd()
    os.chdir(cwd)
    try:
        with contextlib.redirect_stdout(out):
            code = main(list(argv))
    finally:
        os.chdir(here)
    return {"code": code, "out": out.getvalue()}


done = {"file": rockyade.__file__, "files": [str(f) for f in files("rockyade")]}
done["params"] = call("params", "--specimen", "1")
done["tables"] = call("tables")
done["calibrate"] = call("calibrate", "--specimen", "1")
done["run"] = call("run", "scene.toml", "--solver", "housner", "--out", "sub/h.csv")
done["record"] = call("run", "specimen1_record.toml", "--solver", "housner", "--out", "r/rec.csv", cwd="ex")
print(json.dumps(done))
"""


def test_the_wheel_carries_the_package_data_and_runs_from_another_folder(installed, tmp_path):
    """The console script copies the examples out (package data) and runs YADE (its driver
    script and payload from the wheel); the other commands run through ``rockyade.cli.main`` in
    one process of the installed Python, numba's JIT off there: compiling Housner's kernel into
    the new site-packages (numba's cache is per installed file, some 9 s of CPU) checks nothing
    of the wheel that the checkout's tests do not (the same source), while the run, its
    relative paths and the record read from the copied examples are the wheel's."""
    work = tmp_path / "elsewhere"
    work.mkdir()
    shutil.copy(EXAMPLES / "specimen1_free.toml", work / "scene.toml")
    rockyade = str(installed / "rockyade")
    # The examples come with the wheel: copied out, a scene that reads a record runs from there
    listed = _run([rockyade, "examples", "--out", "ex"], work).stdout
    assert "ex/records/ec8_type2_D_record21.AT2" in listed and "ex/studies/harmonic_sweep.toml" in listed
    for name in ("specimen1_free.toml", "assemblies/frame.toml", "records/ricker_pulse_T0.5s.AT2"):
        assert (work / "ex" / name).read_bytes() == (EXAMPLES / name).read_bytes()

    commands = _run([str(installed / "python"), "-c", COMMANDS], work, NUMBA_DISABLE_JIT="1")
    done = json.loads(commands.stdout)
    assert str(ROOT) not in done["file"] and "site-packages" in done["file"]  # not the checkout
    listed = str(done["files"])
    assert "licenses/LICENSE" in listed and "paper/data/table5_dem_single.csv" in listed
    assert "rockyade/examples/specimen1_record.toml" in listed
    assert all(done[name]["code"] == 0 for name in ("params", "tables", "calibrate", "run", "record")), commands.stderr
    assert "alpha" in done["params"]["out"]
    assert "Table 5" in done["tables"]["out"] or "table 5" in done["tables"]["out"].lower()
    assert "b_eq" in done["calibrate"]["out"] and "Eq 10" in done["calibrate"]["out"]
    assert json.loads((work / "sub/h.json").read_text())["status"] == "completed"
    assert json.loads((work / "ex/r/rec.json").read_text())["status"] == "completed"
    # YADE: the driver script and the payload come from the wheel; a relative output folder
    if not yade_backend.yade_available():
        message = f"YADE is not installed ({yade_backend.YADE_PYTHON}): apt-get install yade"
        if os.environ.get("ROCKYADE_REQUIRE_YADE") == "1":
            pytest.fail(message)
        pytest.skip(message)
    _run([rockyade, "run", "scene.toml", "--solver", "yade", "--out", "sub/y.csv"], work)
    assert json.loads((work / "sub/y.json").read_text())["status"] == "completed"
