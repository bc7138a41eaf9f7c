"""The YADE backend, with YADE really running (Debian package).

Skipped only where YADE is absent and ROCKYADE_REQUIRE_YADE is not set; ``make test``
(and so CI) sets it, so a missing YADE fails the suite instead of skipping it.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import re
import signal
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from rockyade import paper
from rockyade.blocks.restitution import effective_restitution, find_peaks
from rockyade.calibration.calibrate import calibrate
from rockyade.calibration.model_stage import calibrated_model
from rockyade.result import Result
from rockyade.runner import Executor, solve_scenes
from rockyade.scene import ContactSpec, load_scene, scene_from_dict
from rockyade.solvers.housner import HousnerSolver
from rockyade.solvers.reference import ReferenceSolver
from rockyade.solvers.yade import YadeSolver
from rockyade.yade import backend as yade_backend
from rockyade.yade import payload as yade_payload

from .conftest import EXAMPLES
from .processes import alive, descendants, require_yade

#: The matched calibration of a block (``calibrate(block, MATCHED, ...).matched``).
MATCHED = ContactSpec(calibration="matched")

PROBES = Path(__file__).parent / "yade_probes"

pytestmark = pytest.mark.yade


@pytest.fixture(scope="module", autouse=True)
def _yade_present():
    require_yade()


def _matched(example: str):
    scene = load_scene(EXAMPLES / example)
    d = scene.to_dict()
    d["contact"]["calibration"] = "matched"
    return scene_from_dict(d)


#: The probes of YADE's pitfalls (tests/yade_probes/), each printing its JSON line last.
PROBE_FILES = ("inertia_pitfall.py", "default_damping.py")

#: Runs each probe given, in turn, in one Python (each resets YADE's scene before each of its
#: cases). YADE is imported here first: its import needs the main module's namespace.
RUN_PROBES = (
    "import runpy, sys\nsys.path.insert(1, sys.argv[1])\nimport yade\n"
    "for path in sys.argv[2:]:\n    runpy.run_path(path, run_name='__main__')\n"
)


@pytest.fixture(scope="module")
def probes() -> dict[str, dict]:
    """Every probe's JSON, by file name: one start of YADE's Python for all (about 2 s each)."""
    out = subprocess.run(
        [
            yade_backend.YADE_PYTHON,
            "-c",
            RUN_PROBES,
            str(yade_backend.YADE_PY_DIR),
            *(str(PROBES / name) for name in PROBE_FILES),
        ],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "OMP_NUM_THREADS": "1"},
    )
    assert out.returncode == 0, out.stderr
    lines = [json.loads(line) for line in out.stdout.splitlines() if line.startswith("{")]
    assert len(lines) == len(PROBE_FILES), out.stdout
    return dict(zip(PROBE_FILES, lines, strict=True))


# ------------------------------------------------------------------ the pitfalls


def test_pitfall_inertia_under_blocked_rotations(probes):
    """With blocked rotations YADE divides the torque by the clump's principal inertia: the
    default gives the wrong angular acceleration, the isotropic inertia the right one."""
    probe = probes["inertia_pitfall.py"]
    assert probe["isotropic"] == pytest.approx(probe["expected"], rel=1e-9)
    assert abs(probe["principal"] / probe["expected"] - 1) > 0.01


def test_pitfall_default_damping(probes):
    probe = probes["default_damping.py"]
    assert probe["default_damping"] == pytest.approx(0.2)
    assert probe["default"] == pytest.approx(0.8 * probe["expected"], rel=1e-6)
    assert probe["zero"] == pytest.approx(probe["expected"], rel=1e-9)


def _describe(scene, tmp_path) -> tuple[dict, object]:
    model = calibrated_model(scene)
    path = tmp_path / "scene.yade.json"
    path.write_text(json.dumps(yade_payload.scene_payload(model)))
    out = subprocess.run(
        [yade_backend.YADE_PYTHON, str(yade_backend.DRIVER), "--describe", str(path)],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "OMP_NUM_THREADS": "1"},
    )
    assert out.returncode == 0, out.stdout + out.stderr
    return json.loads(out.stdout.strip().splitlines()[-1]), model


def test_driver_handles_every_pitfall(tmp_path):
    """The scene the driver builds: damping 0, O.dt from Eq 7, the recorder first and every
    steps_per_sample steps, exact mass and isotropic inertia at the centroid, planar DOFs, a
    prism per block, zeros on the base and prisms, and on each vertex sphere copy the values
    of the joint of the body its mask meets (the base: the block's own joint; the other block:
    the bi-block's bed joint, the upper block's own)."""
    built, model = _describe(load_scene(EXAMPLES / "biblock_free.toml"), tmp_path)
    assert built["newton_damping"] == 0.0
    assert built["gravity"] == [0.0, -9.81, 0.0]
    assert built["dt"] == pytest.approx(model.dt_s, rel=1e-12)
    assert built["recorder_first"] and built["recorder_period"] == model.steps_per_sample
    assert built["base"]["kn"] == 0.0 and not built["base"]["dynamic"]
    base_mask = built["base"]["mask"]
    prisms = []
    for clump, body, pos0 in zip(built["clumps"], model.bodies, model.pos0_m, strict=True):
        assert clump["mass"] == pytest.approx(body.mass_kg)
        assert clump["inertia"] == pytest.approx([body.inertia_kgm2] * 3)
        assert clump["blocked"] == "zXY"
        assert clump["pos"][:2] == pytest.approx(pos0.tolist(), abs=1e-7)
        assert len(clump["vertex_ids"]) == len(body.contact_vertices_m)
        (prism,) = [m for m in clump["members"] if m["shape"] == "Polyhedra"]
        assert prism["kn"] == 0.0
        prisms.append(prism["mask"])
        helper = [m for m in clump["members"] if m["mask"] == 0]
        assert len(helper) == 1  # the centroid helper never collides
    assert prisms[0] & prisms[1] == 0 and not (prisms[0] | prisms[1]) & base_mask
    lower, upper = model.bodies
    bed = model.joints.params[model.joints.joint_for(0, 1)]
    assert bed.K_N_per_m == upper.joint.K_N_per_m != lower.joint.K_N_per_m  # the upper block's own
    for i, clump in enumerate(built["clumps"]):
        by_id = {mid: m for mid, m in zip(_member_ids(clump), clump["members"], strict=True)}
        for ids in clump["vertex_ids"]:
            copies = [by_id[mid] for mid in ids]
            meets_base = [c for c in copies if c["mask"] & base_mask]
            meets_other = [c for c in copies if c["mask"] & prisms[1 - i]]
            assert not any(c["mask"] & prisms[i] for c in copies) or len(built["clumps"]) > 30
            assert len(meets_other) == 1
            assert meets_other[0]["kn"] == pytest.approx(bed.K_N_per_m)
            assert meets_other[0]["cn"] == pytest.approx(bed.beta_s * bed.K_N_per_m)
            if i == 0:
                own = lower.joint
                assert len(meets_base) == 1 and meets_base[0]["kn"] == pytest.approx(own.K_N_per_m)
            else:
                assert not meets_base or meets_base[0]["kn"] == pytest.approx(upper.joint.K_N_per_m)


def _member_ids(clump: dict) -> list[int]:
    """Body ids of a clump's members, in the driver's order (vertex copies first)."""
    first = min(min(ids) for ids in clump["vertex_ids"])
    return list(range(first, first + len(clump["members"])))


# ------------------------------------------------------------------ no listening socket


def _listening_inodes() -> set[str]:
    inodes = set()
    for name in ("/proc/net/tcp", "/proc/net/tcp6"):
        try:
            lines = Path(name).read_text().splitlines()[1:]
        except FileNotFoundError:
            continue
        inodes |= {line.split()[9] for line in lines if line.split()[3] == "0A"}
    return inodes


def _process_sockets(pid: int) -> set[str]:
    found = set()
    try:
        fds = os.listdir(f"/proc/{pid}/fd")
    except FileNotFoundError:
        return found
    for fd in fds:
        try:
            m = re.match(r"socket:\[(\d+)\]", os.readlink(f"/proc/{pid}/fd/{fd}"))
        except OSError:
            continue
        if m:
            found.add(m.group(1))
    return found


def _listening_while_running(cmd: list[str], seconds: float, until_seen: bool = False) -> tuple[int, int]:
    """(listening sockets seen, samples taken) while ``cmd`` runs (at most ``seconds``; with
    ``until_seen``, until a first one is seen)."""
    proc = subprocess.Popen(
        cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env={**os.environ, "OMP_NUM_THREADS": "1"}
    )
    seen: set[str] = set()
    samples = 0
    start = time.time()
    try:
        while proc.poll() is None and time.time() - start < seconds and not (until_seen and seen):
            seen |= _process_sockets(proc.pid) & _listening_inodes()
            samples += 1
            time.sleep(0.05)
    finally:
        proc.kill()
        proc.wait()
    return len(seen), samples


def test_yade_run_listens_on_no_port(tmp_path):
    """A rockyade YADE run opens no listening socket; the same check finds the two servers
    that the stock ``yade`` launcher opens (so the check can fail)."""
    # 4 s of rocking (8 s before): with YADE's start-up the watcher takes dozens of samples
    scene = scene_from_dict({**load_scene(EXAMPLES / "specimen1_free.toml").to_dict(), "duration_s": 4.0})
    model = calibrated_model(scene)
    path = tmp_path / "s.yade.json"
    path.write_text(json.dumps(yade_payload.scene_payload(model)))
    ours, samples = _listening_while_running(
        [yade_backend.YADE_PYTHON, str(yade_backend.DRIVER), str(path), str(tmp_path / "out.npz")], 60
    )
    assert samples > 10 and ours == 0
    assert (tmp_path / "out.npz").is_file()  # the run went through while being watched
    launcher = Path("/usr/bin/yade")
    if launcher.is_file():
        script = tmp_path / "sleep.py"
        script.write_text("import time\ntime.sleep(6)\n")
        stock, _ = _listening_while_running([str(launcher), "-n", "-x", str(script)], 30, until_seen=True)
        assert stock >= 1


# ------------------------------------------------------------------ cross-checks


@pytest.fixture(scope="module", params=["1", "2", "3", "4"])
def free_rocking(request):
    scene = _matched(f"specimen{request.param}_free.toml")
    return request.param, scene, YadeSolver().run(scene), ReferenceSolver().run(scene)


def test_free_rocking_yade_vs_reference(free_rocking):
    """Matched beta from the reference DEM: first five peaks within 2 %, peak times within
    1 %, effective mu within 0.5 %.

    Specimen 2's matched damping is so light (xi < 1 % at the contact frequency) that its
    corners chatter at impact and single peaks are sensitive to any small change of the
    model: the reference DEM itself moves its peaks by ~8 % when its step is halved. For it,
    YADE must agree with the reference within that intrinsic sensitivity (and mu within 0.5 %).
    """
    key, scene, y, r = free_rocking
    assert y.status == "completed", y.meta.failure_reason
    alpha = scene.blocks[0].alpha_rad
    py, pr = (find_peaks(x.t, x.series("theta_rad"), 1e-3 * alpha) for x in (y, r))
    amp = np.max(np.abs(py.amplitude_rad[:5] / pr.amplitude_rad[:5] - 1))
    times = np.max(np.abs(py.t_s[:5] / pr.t_s[:5] - 1))
    if key != "2":
        assert amp < 0.02 and times < 0.01
    else:
        from rockyade.solvers.reference import run_model

        model = calibrated_model(scene)
        finer = run_model(model.with_dt(model.dt_s / 2), record_energy=False)
        pf = find_peaks(finer.t, finer.series("theta_rad"), 1e-3 * alpha)
        own = np.max(np.abs(pf.amplitude_rad[:5] / pr.amplitude_rad[:5] - 1))
        own_times = np.max(np.abs(pf.t_s[:5] / pr.t_s[:5] - 1))
        assert amp <= max(0.02, 1.2 * own) and times <= max(0.01, 1.2 * own_times, 0.02)
    assert effective_restitution(py, alpha, 4) == pytest.approx(effective_restitution(pr, alpha, 4), rel=0.005)


def test_free_rocking_yade_vs_housner(free_rocking):
    """YADE's effective restitution within 1 % of the exact Housner solution's (mu_E)."""
    key, scene, y, _ = free_rocking
    alpha = scene.blocks[0].alpha_rad
    mu_yade = effective_restitution(find_peaks(y.t, y.series("theta_rad"), 1e-3 * alpha), alpha, 4)
    exact = HousnerSolver().run(scene)
    mu_exact = effective_restitution(find_peaks(exact.t, exact.series("theta_rad"), 1e-3 * alpha), alpha, 4)
    assert mu_exact == pytest.approx(paper.specimen(key).experimental["mu"], rel=1e-4)
    assert mu_yade == pytest.approx(mu_exact, rel=0.01)


def test_theta_sign_follows_the_convention():
    """Released to the right (theta0 < 0) the block first swings to theta > 0, in YADE as
    in the reference DEM: the rotation measure has the right sign both ways."""
    d = load_scene(EXAMPLES / "specimen3_free.toml").to_dict()
    d["motion"]["theta0_rad"] = -0.07
    d["duration_s"] = 1.5
    scene = scene_from_dict(d)
    y, r = YadeSolver().run(scene), ReferenceSolver().run(scene)
    assert y.series("theta_rad")[0] == pytest.approx(-0.07)
    py, pr = (find_peaks(x.t, x.series("theta_rad"), 1e-4) for x in (y, r))
    assert py.theta_rad[0] > 0 and np.sign(py.theta_rad[:3]).tolist() == np.sign(pr.theta_rad[:3]).tolist()
    assert np.max(np.abs(y.series("theta_rad") - r.series("theta_rad"))) < 2e-3


def test_harmonic_yade_vs_reference():
    """Specimen 1 on the shake table at 3.3 Hz, 6 mm: max |theta| within 5 %."""
    scene = load_scene(EXAMPLES / "specimen1_harmonic.toml")
    y, r = YadeSolver().run(scene), ReferenceSolver().run(scene)
    assert y.status == r.status == "completed"
    my, mr = (np.max(np.abs(x.series("theta_rad"))) for x in (y, r))
    assert mr > 0.01  # it rocks
    assert my == pytest.approx(mr, rel=0.05)
    np.testing.assert_allclose(y.frame["ag_m_s2"], r.frame["ag_m_s2"])


def test_biblock_upper_block_yade_vs_reference():
    """Free rocking of the upper block of the stack: YADE and the reference DEM within 3 %
    (first three peaks and their times, both blocks)."""
    scene = load_scene(EXAMPLES / "biblock_free.toml")
    y, r = YadeSolver().run(scene), ReferenceSolver().run(scene)
    assert y.status == "completed", y.meta.failure_reason
    py, pr = (find_peaks(x.t, x.series("theta_rad", "upper"), 1e-4) for x in (y, r))
    assert np.max(np.abs(py.amplitude_rad[:3] / pr.amplitude_rad[:3] - 1)) < 0.03
    assert np.max(np.abs(py.t_s[:3] / pr.t_s[:3] - 1)) < 0.03
    lower_y, lower_r = (np.max(np.abs(x.series("theta_rad", "lower"))) for x in (y, r))
    assert lower_y == pytest.approx(lower_r, rel=0.2)  # the stack interaction appears in both


def test_overturning_in_yade():
    scene = load_scene(EXAMPLES / "specimen1_pulse.toml")
    y, r = YadeSolver().run(scene), ReferenceSolver().run(scene)
    assert y.status == r.status == "overturned"
    assert y.meta.overturn_time_s == pytest.approx(r.meta.overturn_time_s, rel=0.02)
    assert y.t[-1] <= y.meta.overturn_time_s + 1e-9


# ------------------------------------------------------------------ failures and files


def test_exception_inside_yade_gives_failed_result(tmp_path, monkeypatch):
    scene = load_scene(EXAMPLES / "specimen1_free.toml")
    real = yade_payload.scene_payload

    def broken(model):
        payload = real(model)
        del payload["bodies"][0]["sphere_copies"]
        return payload

    monkeypatch.setattr(yade_backend, "scene_payload", broken)
    result = YadeSolver(workdir=tmp_path, stem="bad").run(scene)
    assert result.status == "failed" and not result.ok
    assert "exited with code 1" in result.meta.failure_reason and "KeyError" in result.meta.failure_reason
    assert Path(result.meta.log_path).is_file() and "Traceback" in Path(result.meta.log_path).read_text()
    out = tmp_path / "bad.csv"
    result.write(out)
    back = Result.read(out)
    assert back.status == "failed" and len(back.frame) == 0


def test_instability_inside_yade_gives_failed_result(tmp_path):
    """A time step far above the stability limit (forced past rockyade's own check) makes
    the state non-finite: status failed, with the reason."""
    model = calibrated_model(
        scene_from_dict({**load_scene(EXAMPLES / "specimen1_free.toml").to_dict(), "duration_s": 0.5})
    )
    steps = max(1, math.floor(model.sample_dt_s / (20 * model.dt_stable_s)))
    unstable = replace(model, dt_s=model.sample_dt_s / steps, steps_per_sample=steps, n_samples=501)
    result = yade_backend.run_model(unstable, workdir=tmp_path, name="unstable")
    assert result.status == "failed"
    assert "numerical instability" in result.meta.failure_reason


def _warm_yade() -> None:
    """This thread's warm YADE started (a loaded machine can take the whole of a short timeout
    to start YADE, and a run stopped before its first sample has none to keep)."""
    assert (
        YadeSolver()
        .run(scene_from_dict({**load_scene(EXAMPLES / "specimen3_free.toml").to_dict(), "duration_s": 0.2}))
        .ok
    )


#: A run no machine finishes within the tests' timeouts (0.5 to 1 s): an hour of specimen 1
#: rocking (7.2e7 body-steps, minutes of YADE on the fastest machine seen, where 60 s of
#: it, the earlier choice, finished within 3 s), sampled every 0.01 s to stay within the
#: cost limits.
NEVER_FINISHES = {"duration_s": 3600.0, "sample_dt_s": 0.01}


def test_timeout_gives_failed_result(tmp_path):
    scene = scene_from_dict({**load_scene(EXAMPLES / "specimen1_free.toml").to_dict(), **NEVER_FINISHES})
    _warm_yade()
    start = time.time()
    result = YadeSolver(workdir=tmp_path, stem="slow", timeout_s=1.0).run(scene)
    assert time.time() - start < 30
    assert result.status == "failed" and result.meta.failure_reason.startswith("timeout")
    # stopped by the driver at the deadline: what it recorded is kept, marked partial
    assert result.meta.partial is True and result.meta.partial_samples == len(result.frame) > 0
    assert not list(tmp_path.glob("*.part"))


def test_partial_output_is_not_a_result(tmp_path):
    model = calibrated_model(load_scene(EXAMPLES / "specimen1_free.toml"))
    good = yade_backend.run_model(model, workdir=tmp_path, name="ok")
    assert good.ok
    npz = tmp_path / "ok.yade.npz"
    data = npz.read_bytes()
    npz.write_bytes(data[: len(data) // 2])
    parsed = yade_backend._parse(model, npz, None, tmp_path / "ok.yade.log", 1.0, None)
    assert parsed.status == "failed" and "unreadable" in parsed.meta.failure_reason
    npz.unlink()
    missing = yade_backend._parse(model, npz, None, tmp_path / "ok.yade.log", 1.0, None)
    assert missing.status == "failed" and "no output" in missing.meta.failure_reason


def test_parallel_runs_do_not_interfere():
    base = load_scene(EXAMPLES / "specimen3_free.toml").to_dict()
    scenes = [
        scene_from_dict({**base, "duration_s": 1.5, "motion": {"type": "free", "theta0_rad": th}})
        for th in (0.03, 0.06)
    ]
    parallel = solve_scenes(YadeSolver(), scenes, executor=Executor("threads", 2))
    serial = [YadeSolver().run(s) for s in scenes]
    for a, b in zip(parallel, serial, strict=True):
        assert a.ok and b.ok
        np.testing.assert_array_equal(a.series("theta_rad"), b.series("theta_rad"))


def test_cli_run_yade_keeps_log_beside_result(tmp_path, capsys):
    from rockyade.cli import main

    out = tmp_path / "r.csv"
    assert main(["run", str(EXAMPLES / "specimen3_free.toml"), "--solver", "yade", "--out", str(out)]) == 0
    result = Result.read(out)
    assert result.meta.solver == "yade" and result.meta.version.startswith("YADE 2023")
    assert (tmp_path / "r.yade.log").is_file() and (tmp_path / "r.yade.json").is_file()
    assert "c0_fn_N" in result.frame.columns


def test_cli_compare_three_solvers(tmp_path, capsys):
    from rockyade.cli import main

    code = main(
        [
            "compare",
            str(EXAMPLES / "specimen1_free.toml"),
            "--solvers",
            "housner,reference,yade",
            "--out",
            str(tmp_path),
        ]
    )
    assert code == 0
    table = __import__("pandas").read_csv(tmp_path / "specimen1_free_compare.csv")
    # the reference DEM is what the others are compared with, never with itself (its values: reference_value)
    assert set(table["solver"]) == {"housner", "yade"} and set(table["reference"]) == {"reference"}
    metrics = set(table["metric"])
    for m in (
        "peak1_amplitude_rad",
        "peak1_time_s",
        "mu_eff",
        "max_abs_theta_rad",
        "overturned",
        "overturn_time_s",
        "rms_theta_difference_rad",
    ):
        assert m in metrics
    rms = table[(table.solver == "yade") & (table.metric == "rms_theta_difference_rad")]["value"].iloc[0]
    assert rms < 1e-3
    assert (tmp_path / "specimen1_free_compare.png").stat().st_size > 5000


def test_matched_beta_comes_from_the_reference_dem():
    scene = _matched("specimen1_free.toml")
    model = calibrated_model(scene)
    s = paper.specimen(1)
    assert model.bodies[0].joint.beta_s == pytest.approx(calibrate(s.block(), MATCHED, **s.experimental).matched.beta_s)
    assert model.bodies[0].joint.method == "matched"


# ------------------------------------------------------------------ relative paths, timeout, script


def _short_scene_file(folder: Path, duration: float = 0.6) -> Path:
    d = load_scene(EXAMPLES / "specimen3_free.toml").to_dict()
    d["duration_s"] = duration
    path = folder / "s3.json"
    path.write_text(json.dumps(d))
    return path


def test_cli_run_yade_with_relative_paths(tmp_path, monkeypatch, capsys):
    """`rockyade run SCENE --solver yade --out sub/x.csv` from the scene's folder (the YADE
    process runs in sub/: it must be given absolute paths)."""
    from rockyade.cli import main

    _short_scene_file(tmp_path)
    monkeypatch.chdir(tmp_path)
    assert main(["run", "s3.json", "--solver", "yade", "--out", "sub/x.csv"]) == 0
    assert Result.read(Path("sub/x.csv")).meta.solver == "yade"
    assert Path("sub/x.yade.log").is_file() and Path("sub/x.yade.json").is_file()


def test_cli_compare_with_relative_out(tmp_path, monkeypatch, capsys):
    from rockyade.cli import main

    _short_scene_file(tmp_path)
    monkeypatch.chdir(tmp_path)
    assert main(["compare", "s3.json", "--solvers", "reference,yade", "--out", "compare/"]) == 0
    table = __import__("pandas").read_csv("compare/s3_compare.csv")
    assert set(table["solver"]) == {"yade"} and set(table["reference"]) == {"reference"}
    assert Result.read(Path("compare/s3_yade.csv")).ok


def test_cli_batch_with_relative_out(tmp_path, monkeypatch, capsys):
    """A study with YADE runs, its output folder relative (as `make run` gives it)."""
    from rockyade.cli import main

    _short_scene_file(tmp_path)
    (tmp_path / "study.toml").write_text(
        'name = "rel"\nsolvers = ["yade"]\nyade_timeout_s = 600\n[base]\nfile = "s3.json"\n'
        '[grid]\n"motion.theta0_rad" = [0.03, 0.05]\n'
    )
    monkeypatch.chdir(tmp_path)
    assert main(["batch", "study.toml", "--out", "reports/rel", "--workers", "1", "--quiet"]) == 0
    summary = __import__("pandas").read_csv("reports/rel/summary.csv")
    assert list(summary["status"]) == ["completed", "completed"]


def test_default_timeout_grows_with_the_work_and_is_capped():
    model = calibrated_model(load_scene(EXAMPLES / "specimen1_free.toml"))
    short = yade_backend.default_timeout(model)
    assert short == pytest.approx(yade_backend.TIMEOUT_STARTUP_S + yade_backend.TIMEOUT_PER_BODY_STEP_S * model.n_steps)
    longer = replace(model, n_samples=10 * model.n_samples)
    assert yade_backend.default_timeout(longer) > short
    huge = replace(model, n_samples=10_000 * model.n_samples)
    assert yade_backend.default_timeout(huge) == yade_backend.TIMEOUT_CAP_S == 3600.0


def test_cli_yade_timeout_stops_the_run(tmp_path, monkeypatch, capsys):
    """--yade-timeout: a failed result saying so with the samples recorded up to the stop
    (partial), exit 1, and no YADE process left running the scene."""
    from rockyade.cli import main

    d = load_scene(EXAMPLES / "specimen1_free.toml").to_dict()
    d.update(NEVER_FINISHES)
    (tmp_path / "long.json").write_text(json.dumps(d))
    monkeypatch.chdir(tmp_path)
    before = descendants(os.getpid())
    _warm_yade()
    start = time.time()
    code = main(["run", "long.json", "--solver", "yade", "--out", "t/long.csv", "--yade-timeout", "1"])
    assert code == 1 and time.time() - start < 30
    out = capsys.readouterr().out
    assert "timeout: YADE did not finish within 1 s" in out
    kept = Result.read(Path("t/long.csv"))
    assert kept.status == "failed" and kept.meta.partial is True and len(kept.frame) > 0
    # the scene was stopped: its warm YADE waits idle for the next one, and quits when asked
    from rockyade.yade.backend import QUIT_WAIT_S, close_workers

    start = time.monotonic()
    close_workers()
    assert time.monotonic() - start < QUIT_WAIT_S
    assert not [p for p in descendants(os.getpid()) - before if alive(p)]


def test_a_failed_run_never_replaces_a_complete_result(tmp_path, monkeypatch, capsys):
    """A complete result at --out stays byte for byte when a later run to the same path fails
    (a YADE timeout): the failed one goes beside it as <stem>_failed.csv, marked partial; a
    failed result at --out (not complete) is replaced as any other."""
    from rockyade.cli import main

    d = load_scene(EXAMPLES / "specimen1_free.toml").to_dict()
    d.update(NEVER_FINISHES)
    (tmp_path / "long.json").write_text(json.dumps(d))
    monkeypatch.chdir(tmp_path)
    # the complete result: a short scene (an hour of Housner's samples, written as CSV, before)
    (tmp_path / "short.json").write_text(json.dumps({**d, "duration_s": 0.5, "sample_dt_s": 0.01}))
    assert main(["run", "short.json", "--solver", "housner", "--out", "r/long.csv"]) == 0
    before = {p.name: p.read_bytes() for p in Path("r").iterdir()}
    _warm_yade()
    assert main(["run", "long.json", "--solver", "yade", "--out", "r/long.csv", "--yade-timeout", "1"]) == 1
    assert "keeps the complete result of an earlier run" in capsys.readouterr().out
    assert {p.name: p.read_bytes() for p in Path("r").iterdir() if p.name in before} == before
    assert Result.read(Path("r/long.csv")).status == "completed"
    failed = Result.read(Path("r/long_failed.csv"))
    assert failed.status == "failed" and failed.meta.partial is True
    # a failed result is not worth keeping over another failed one (with samples or without)
    assert main(["run", "long.json", "--solver", "yade", "--out", "r/long_failed.csv", "--yade-timeout", "0.5"]) == 1
    assert not Path("r/long_failed_failed.csv").exists()


def test_a_failed_yade_run_never_touches_a_complete_runs_files(tmp_path, monkeypatch, capsys):
    """A complete YADE run at --out, then a run to the same --out that times out: the complete
    run's CSV, JSON, scene data, output and log stay byte for byte, and its JSON's log_path
    names its own log; the failed run's files go beside as <stem>_failed.*. The timeout used to
    delete the old .yade.npz and overwrite .yade.log."""
    from rockyade.cli import main

    d = load_scene(EXAMPLES / "specimen1_free.toml").to_dict()
    (tmp_path / "short.json").write_text(json.dumps({**d, "duration_s": 0.5}))
    (tmp_path / "long.json").write_text(json.dumps({**d, **NEVER_FINISHES}))
    monkeypatch.chdir(tmp_path)
    assert main(["run", "short.json", "--solver", "yade", "--out", "r/x.csv"]) == 0
    before = {p.name: p.read_bytes() for p in Path("r").iterdir()}
    assert {"x.csv", "x.json", "x.yade.json", "x.yade.npz", "x.yade.log"} <= set(before)
    _warm_yade()
    assert main(["run", "long.json", "--solver", "yade", "--out", "r/x.csv", "--yade-timeout", "1"]) == 1
    capsys.readouterr()
    assert {p.name: p.read_bytes() for p in Path("r").iterdir() if p.name in before} == before
    complete = Result.read(Path("r/x.csv"))
    assert complete.status == "completed" and Path(complete.meta.log_path).name == "x.yade.log"
    failed = Result.read(Path("r/x_failed.csv"))
    assert failed.status == "failed" and Path(failed.meta.log_path).name == "x_failed.yade.log"
    assert Path("r/x_failed.yade.log").is_file() and not list(Path("r").glob("*.running.*"))


@pytest.mark.parametrize("value", ["0", "-5", "nan", "1e12"])
def test_cli_bad_yade_timeout_is_refused(value, tmp_path, capsys):
    from rockyade.cli import main

    code = main(["run", str(EXAMPLES / "specimen3_free.toml"), "--solver", "yade", "--yade-timeout", value])
    assert code == 2
    assert "--yade-timeout" in capsys.readouterr().err


def test_yade_script_runs_without_the_launcher(tmp_path, monkeypatch, capsys):
    """`rockyade yade-script` writes run.py + scene.json; Debian's python3.11 with YADE's
    modules runs it (no launcher, no server) and writes the same output as the backend."""
    from rockyade.cli import main

    _short_scene_file(tmp_path)
    monkeypatch.chdir(tmp_path)
    assert main(["yade-script", "s3.json", "--out", "by_hand"]) == 0
    assert "yade -x by_hand/run.py" in capsys.readouterr().out
    script = Path("by_hand/run.py")
    assert "json" in script.read_text() and Path("by_hand/scene.json").is_file()
    proc = subprocess.run(
        [yade_backend.YADE_PYTHON, str(script)],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "OMP_NUM_THREADS": "1"},
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    scene = load_scene(Path("s3.json"))
    model = calibrated_model(scene)
    by_hand = yade_backend._parse(model, Path("by_hand/result.npz"), None, Path("none.log"), 0.0, None)
    backend = YadeSolver().run(scene)
    assert by_hand.ok and backend.ok
    np.testing.assert_array_equal(by_hand.series("theta_rad"), backend.series("theta_rad"))
    table = __import__("pandas").read_csv("by_hand/result.csv")
    np.testing.assert_allclose(table["specimen3_rotation_rad"], backend.series("theta_rad"), atol=1e-9)


def test_study_file_yade_timeout(tmp_path):
    """``yade_timeout_s`` in a study file reaches every task; a bad value names the key."""
    from rockyade.batch import load_study, study_tasks
    from rockyade.errors import InputError

    _short_scene_file(tmp_path)
    body = '\nsolvers = ["yade"]\n[base]\nfile = "s3.json"\n'
    (tmp_path / "ok.toml").write_text("yade_timeout_s = 90" + body)
    assert {t.solver.timeout_s for t in study_tasks(load_study(tmp_path / "ok.toml"))} == {90.0}
    (tmp_path / "bad.toml").write_text("yade_timeout_s = -1" + body)
    with pytest.raises(InputError, match="yade_timeout_s"):
        load_study(tmp_path / "bad.toml")


def test_yade_dies_with_a_sigkilled_parent(tmp_path):
    """No clean-up code runs on SIGKILL: the kernel must end YADE with the rockyade process
    that started it (otherwise YADE runs on, an orphan, to the end of its simulation)."""
    d = load_scene(EXAMPLES / "specimen1_free.toml").to_dict()
    d.update(duration_s=600.0, sample_dt_s=0.01)  # minutes of YADE: it is running when the parent dies
    scene = tmp_path / "long.json"
    scene.write_text(json.dumps(d))
    parent = subprocess.Popen(
        [sys.executable, "-m", "rockyade", "run", str(scene), "--solver", "yade", "--out", "r.csv", "--allow-large"],
        cwd=tmp_path,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    yade: list[int] = []
    try:
        deadline = time.monotonic() + 60
        while not yade and time.monotonic() < deadline and parent.poll() is None:
            time.sleep(0.2)
            yade = sorted(descendants(parent.pid))
        assert yade, "rockyade never started YADE"
        time.sleep(0.5)
        parent.kill()
        parent.wait()
        deadline = time.monotonic() + 10
        while any(alive(p) for p in yade) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not any(alive(p) for p in yade), "YADE outlived the process that started it"
    finally:
        parent.kill()
        parent.wait()
        for p in yade:  # never leave an orphan behind, even when the test fails
            with contextlib.suppress(OSError):
                os.kill(p, signal.SIGKILL)
