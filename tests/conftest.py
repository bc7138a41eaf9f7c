"""Shared fixtures and helpers for the test suite."""

from __future__ import annotations

import json
import math
import os
import resource
import tempfile
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
#: An EC8 site (Type 1, ground B, ag = 0.25 g) and the knowledge level LC1 (FC = 1.35) of ``rockyade assess``.
EC8_LC1 = ["--knowledge-level", "LC1", "--spectrum-type", "1", "--ground", "B", "--ag", "0.25g"]

#: Environment variable naming a folder of external records (PEER NGA .AT2 files) that
#: some tests read. rockyade ships no real record; these tests skip when it is unset.
RECORDS_ENV = "ROCKYADE_RECORDS_DIR"


def external_records_dir() -> Path | None:
    """The folder named by ``$ROCKYADE_RECORDS_DIR``, or None when it is unset or empty."""
    value = os.environ.get(RECORDS_ENV, "").strip()
    return Path(value).expanduser() if value else None


def needs_records(*names: str) -> pytest.MarkDecorator:
    """Skip a test unless ``$ROCKYADE_RECORDS_DIR`` holds every one of ``names``."""
    folder = external_records_dir()
    if folder is None:
        reason = f"external records: set {RECORDS_ENV} to a folder holding {', '.join(names)} (PEER NGA)"
    else:
        missing = [name for name in names if not (folder / name).is_file()]
        reason = f"external records: {RECORDS_ENV}={folder} lacks {', '.join(missing)}" if missing else ""
    return pytest.mark.skipif(bool(reason), reason=reason)


def free_scene_dict(theta0: float = 0.1175, duration: float = 4.0, **block_overrides) -> dict:
    """Specimen 1 free rocking, as in the issue, with optional block overrides."""
    block = {
        "name": "specimen1",
        "width_m": 0.25,
        "height_m": 1.0,
        "thickness_m": 0.754,
        "mass_kg": 503,
        "alpha_rad": 0.235,
        "p_rad_s": 3.84,
        "mu": 0.936,
    }
    block.update(block_overrides)
    block = {k: v for k, v in block.items() if v is not None}
    return {
        "duration_s": duration,
        "sample_dt_s": 0.001,
        "blocks": [block],
        "contact": {"calibration": "paper"},
        "motion": {"type": "free", "theta0_rad": theta0},
    }


@pytest.fixture(scope="session", autouse=True)
def _temporary_files_in_pytests_folder(tmp_path_factory: pytest.TempPathFactory):
    """Every temporary file of the session (this process's, and its children's: CLI runs,
    engines' workers, Dask's scratch space) in a folder of pytest's own base folder, which
    pytest keeps for its last three sessions only: the tests that provoke failures or kill runs
    leave what a failed run keeps by design (a failed Siconos run's private folder, a killed
    Dask worker's scratch space) there, not in the system's temporary folder for good. The
    tests of what a run leaves behind set TMPDIR themselves."""
    folder = tmp_path_factory.mktemp("tmp", numbered=False)
    before = os.environ.get("TMPDIR")
    os.environ["TMPDIR"] = str(folder)
    tempfile.tempdir = None  # tempfile caches the folder it found first
    yield
    if before is None:
        os.environ.pop("TMPDIR", None)
    else:
        os.environ["TMPDIR"] = before
    tempfile.tempdir = None


@pytest.fixture
def examples_dir() -> Path:
    return EXAMPLES


def rel(a: float, b: float) -> float:
    """Relative difference |a - b| / |b|."""
    return abs(a - b) / abs(b) if b else math.inf


#: The engines that run in another Python: each a marker that ``make check`` leaves to ``make test``,
#: and its name in rockyade's workers (rockyade.io.warm_program.STARTED).
ENGINE_MARKERS = {"yade": "YADE", "siconos": "Siconos"}


@pytest.fixture(scope="module")
def siconos_present() -> None:
    """Debian's Siconos installed, or the test skipped (failed where ``ROCKYADE_REQUIRE_SICONOS=1``):
    a test that uses it runs the real Siconos and is marked ``siconos``."""
    from .processes import require_siconos

    require_siconos()


@pytest.fixture(autouse=True)
def _engines_run_only_where_marked(request: pytest.FixtureRequest):
    """The gate's own check: a test that starts a worker of a real engine (YADE, Siconos) in
    this process is marked with its name, so that ``make check`` never runs one."""
    from rockyade.io.warm_program import STARTED

    before = dict(STARTED)
    yield
    for engine, label in ENGINE_MARKERS.items():
        if STARTED[label] > before.get(label, 0) and request.node.get_closest_marker(engine) is None:
            pytest.fail(f"started {label} without the marker {engine!r} (tests/conftest.py)", pytrace=False)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """A test that runs a real engine is marked with its name, so that ``make check``
    (``-m "not slow and not yade and not siconos"``) leaves it to ``make test``: a test run
    with the parameter ``"yade"`` or ``"siconos"`` (a solver), and a test that uses the
    fixture ``siconos_present``."""
    for item in items:
        callspec = getattr(item, "callspec", None)
        values = [v for v in callspec.params.values() if isinstance(v, str)] if callspec is not None else []
        for engine in ENGINE_MARKERS:
            if engine in values or f"{engine}_present" in getattr(item, "fixturenames", ()):
                item.add_marker(getattr(pytest.mark, engine))


#: Environment variable naming a file that receives, one JSON line per test, its wall and CPU
#: seconds (this process and the children it waited for: subprocesses, CLI runs, engines'
#: workers that ended; the docs' commands forked by test_docs.py's starter, whose own end, with
#: all of theirs again, falls to the worker's last test); each xdist worker appends to its own
#: ``<file>.<worker>``. Unset: nothing.
CPU_LOG_ENV = "ROCKYADE_TEST_CPU_LOG"


def _cpu_s() -> tuple[float, float]:
    """CPU seconds (user + system) of this process and of its waited-for children."""
    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime, children.ru_utime + children.ru_stime


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item: pytest.Item, nextitem: pytest.Item | None):
    """With ``$ROCKYADE_TEST_CPU_LOG`` set, log each test's wall and CPU time (set-up, call and
    tear-down together), its worker's pid and its start (Unix time, s): the suite's cost measured
    where the machine is shared, and, with the pid and start, the processes a test started (as
    process accounting lists them) found."""
    log = os.environ.get(CPU_LOG_ENV)
    if not log:
        yield
        return
    own0, children0 = _cpu_s()
    started_at = time.time()
    start = time.perf_counter()
    yield
    wall = time.perf_counter() - start
    own1, children1 = _cpu_s()
    worker = os.environ.get("PYTEST_XDIST_WORKER", "main")
    forked = sum(value for name, value in item.user_properties if name == "forked_cpu_s")  # test_docs.py's
    row = {
        "test": item.nodeid,
        "pid": os.getpid(),
        "started_at": started_at,
        "wall_s": wall,
        "cpu_s": own1 - own0,
        "children_cpu_s": children1 - children0 + forked,
    }
    with open(f"{log}.{worker}", "a", encoding="utf-8") as out:
        out.write(json.dumps(row) + "\n")


def pytest_sessionstart(session: pytest.Session) -> None:
    """Compile, once and before any test, the solvers' numba code that numba's cache lacks
    (``make setup`` compiles it: then this only looks): else each ``pytest -n 2`` worker would
    compile the same kernels at once. An xdist worker leaves it to the controller."""
    if hasattr(session.config, "workerinput"):
        return
    from rockyade.solvers.compile_cache import compile_all

    compile_all(lambda line: print(f"rockyade: {line}", flush=True), missing_only=True)
