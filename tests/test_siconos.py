"""Siconos as a solver (rockyade.solvers.siconos), with Debian's Siconos really running:
Housner's restitution out of the model, a pulse against Housner with the time step halved,
a stack at rest, a failure that keeps its samples, no listening socket, options refused by
name. Skipped only where python3-siconos is absent; ``ROCKYADE_REQUIRE_SICONOS=1`` (``make
test``) turns that into a failure."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from rockyade.blocks.classical import classical_parameters
from rockyade.blocks.restitution import find_peaks, restitution_per_impact
from rockyade.errors import InputError
from rockyade.scene import load_scene, scene_from_dict
from rockyade.scene.generators import rest_motion, stack
from rockyade.siconos import backend as siconos_backend
from rockyade.siconos.calibration import DT_PEAK_RTOL, model_restitution
from rockyade.solvers import make_solver
from rockyade.solvers.siconos import SiconosSolver

from .conftest import EXAMPLES
from .processes import listening_of_tree, sigint_default

RECORDS = EXAMPLES / "records"


pytestmark = pytest.mark.usefixtures("siconos_present")  # the real Siconos: marked siconos (conftest)


def _block(width: float, height: float, motion: dict, duration: float, sample_dt: float = 0.002):
    return scene_from_dict(
        {
            "duration_s": duration,
            "sample_dt_s": sample_dt,
            "blocks": [
                {"name": "b", "width_m": width, "height_m": height, "thickness_m": 0.5, "density_kg_m3": 2000.0}
            ],
            "contact": {"calibration": "paper"},
            "motion": motion,
        }
    )


def test_free_rocking_restitution_is_housners_eq4():
    """Specimen 1's geometry (0.25 x 1.0 m) released at alpha/2 with e = 0: every impact's
    restitution within 0.5 % of Housner's 1 - 1.5 sin^2 alpha and of the general polygon
    formula at dt 2.5e-4 s, and within 1 % at the default time step (recorded in meta; an
    impact falls anywhere in its step: at the default step the impacts scatter by 0.7 %)."""
    block = _block(0.25, 1.0, {"type": "free", "theta0_rad": 0.5 * math.atan(0.25)}, 3.0)
    alpha = math.atan(0.25)
    eq4 = 1.0 - 1.5 * math.sin(alpha) ** 2
    general = classical_parameters(block.blocks[0].block()).mu
    assert general == pytest.approx(eq4, rel=1e-9)
    for solver, rtol in ((SiconosSolver(dt_s=2.5e-4), 0.005), (SiconosSolver(), 0.01)):
        result = solver.run(block)
        assert result.ok, result.meta.failure_reason
        assert result.meta.extra["mu_model"]["b"] == pytest.approx(eq4, rel=1e-9)
        peaks = find_peaks(result.frame["t_s"].to_numpy(), result.frame["theta_rad"].to_numpy())
        per_impact = restitution_per_impact(peaks, alpha)[:6]
        assert len(per_impact) >= 4
        assert np.all(np.abs(per_impact / eq4 - 1.0) < rtol), (per_impact, result.meta.dt_s)
    meta = result.meta
    assert meta.dt_factor == 1.0 and 0 < meta.dt_s <= 1e-3 and meta.extra["dt_source"].startswith("default")
    assert meta.unconverged_steps == 0 and meta.extra["solver_calls"] > 0
    assert 0.0 <= meta.extra["max_penetration_m"] < 1e-3


def test_a_newton_restitution_does_not_raise_the_per_cycle_mu():
    """The same release with e = 0.5 at the corners, at dt 2.5e-4 s: each impact's restitution
    is still Housner's within 0.5 % (the landing corner's rebounds end with it at rest, angular
    momentum about it conserved), which is why a target mu above it is refused."""
    block = _block(0.25, 1.0, {"type": "free", "theta0_rad": 0.5 * math.atan(0.25)}, 3.0)
    result = make_solver("siconos", restitution=0.5, dt_s=2.5e-4).run(block)
    assert result.ok, result.meta.failure_reason
    alpha = math.atan(0.25)
    eq4 = 1.0 - 1.5 * math.sin(alpha) ** 2
    peaks = find_peaks(result.frame["t_s"].to_numpy(), result.frame["theta_rad"].to_numpy())
    per_impact = restitution_per_impact(peaks, alpha)[:4]
    assert len(per_impact) == 4
    assert np.all(np.abs(per_impact / eq4 - 1.0) < 0.005), per_impact


def test_a_pulse_matches_housner_and_halving_the_step_changes_the_peak_little():
    """A block 0.17 x 1.0 m under the shipped Ricker pulse scaled to 0.3 g: the peak within 3 %
    of Housner's exact solution, and dt halved (dt_factor 0.5) moves it by less than
    DT_PEAK_RTOL (the stated tolerance of the default step)."""
    scene = _block(
        0.17,
        1.0,
        {"type": "record", "file": str(RECORDS / "ricker_pulse_T0.5s.AT2"), "target_pga_m_s2": 0.3 * 9.81},
        2.8,
    )
    housner = make_solver("housner").run(scene)
    full = SiconosSolver().run(scene)
    half = SiconosSolver(dt_factor=0.5).run(scene)
    assert full.ok and half.ok and housner.ok
    assert half.meta.dt_s == pytest.approx(0.5 * full.meta.dt_s, rel=1e-9)
    assert half.meta.dt_factor == 0.5

    def peak(r):
        return float(np.max(np.abs(r.frame["theta_rad"].to_numpy())))

    assert peak(full) > 0.01  # it rocks
    assert peak(half) == pytest.approx(peak(full), rel=DT_PEAK_RTOL)
    assert peak(full) == pytest.approx(peak(housner), rel=0.03)


def test_a_two_block_stack_stands_at_rest_with_the_dems_columns():
    """Two blocks stacked on the base stay put (rigid contacts: no settlement), and the
    Result has the reference DEM's per-block columns (its energy columns aside)."""
    data = stack(widths_m=[0.4, 0.35], heights_m=0.5, motion=rest_motion(), duration_s=0.6, sample_dt_s=0.01)
    scene = scene_from_dict(data)
    result = SiconosSolver().run(scene)
    assert result.ok, result.meta.failure_reason
    for name in ("b01", "b02"):
        assert np.max(np.abs(result.frame[f"{name}_theta_rad"])) < 1e-6
        assert np.max(np.abs(result.frame[f"{name}_x_m"])) < 1e-5
        assert np.max(np.abs(result.frame[f"{name}_y_m"])) < 1e-5
    assert result.frame["b02_n_contacts"].iloc[-1] == 2  # the two ends of the bed joint
    assert result.frame["b01_c0_fn_N"].iloc[-1] > 0 and result.frame["b01_c1_fn_N"].iloc[-1] > 0
    weight = sum(b.block().mass_kg for b in scene.blocks) * 9.81
    base = result.frame["b01_c0_fn_N"].iloc[-1] + result.frame["b01_c1_fn_N"].iloc[-1]
    assert base == pytest.approx(weight, rel=1e-3)
    reference = make_solver("reference").run(scene)
    missing = {c for c in reference.frame.columns if not c.startswith(("energy_", "work_"))} - set(result.frame.columns)
    assert not missing
    assert result.meta.status == "completed" and result.meta.blocks == ("b01", "b02")


def test_a_tapered_four_block_stack_stands_at_rest():
    """Four blocks, narrowing upwards (two contacts per bed joint: hyperstatic), stay put:
    the vertex-to-edge contacts and the nonsmooth Newton hold them to well under 0.1 mm (the
    Bullet vertex-disk model rocked as a whole within 0.2 s)."""
    data = stack(
        widths_m=[0.6, 0.52, 0.44, 0.36], heights_m=0.4, motion=rest_motion(), duration_s=0.3, sample_dt_s=0.01
    )
    result = SiconosSolver(dt_s=1e-3).run(scene_from_dict(data))
    assert result.ok, result.meta.failure_reason
    for name in ("b01", "b02", "b03", "b04"):
        assert np.max(np.abs(result.frame[f"{name}_theta_rad"])) < 1e-6
        assert np.max(np.abs(result.frame[f"{name}_x_m"] - result.frame[f"{name}_x_m"].iloc[0])) < 1e-4
        assert np.max(np.abs(result.frame[f"{name}_y_m"] - result.frame[f"{name}_y_m"].iloc[0])) < 1e-4
    assert result.frame["b04_n_contacts"].iloc[-1] == 2
    assert result.meta.extra["solver_iterations_mean"] < 50


def test_a_run_siconos_cannot_converge_fails_and_keeps_its_samples():
    """One friction-solver iteration per step cannot hold a stack (it blows up or stays
    unconverged): the run is ``failed``, says why, and keeps the samples it recorded
    (``partial``), never looking complete."""
    data = stack(widths_m=[0.4, 0.35], heights_m=0.5, motion=rest_motion(), duration_s=0.3, sample_dt_s=0.01)
    result = SiconosSolver(solver_max_iter=1).run(scene_from_dict(data))
    assert result.status == "failed" and not result.ok
    reason = result.meta.failure_reason
    assert "did not converge" in reason or "numerical instability" in reason
    assert result.meta.partial is True and len(result.frame) == result.meta.partial_samples > 0
    assert result.meta.unconverged_steps > 0


def test_a_timeout_fails_and_keeps_the_samples_so_far():
    """A run that cannot finish in its time (10,000 s of rocking in 1 s of wall time; its worker
    started by a short run first, so that the 1 s is the run's, not Siconos's start-up)."""
    assert SiconosSolver().run(_block(0.25, 1.0, {"type": "free", "theta0_rad": 0.1}, 0.2)).ok
    scene = _block(0.25, 1.0, {"type": "free", "theta0_rad": 0.1}, 10_000.0, sample_dt=0.01)
    result = SiconosSolver(timeout_s=1.0).run(scene)
    assert result.status == "failed" and "timeout" in result.meta.failure_reason
    assert result.meta.partial is True and 0 < len(result.frame) < scene.n_samples
    again = SiconosSolver().run(_block(0.25, 1.0, {"type": "free", "theta0_rad": 0.1}, 0.2))
    assert again.ok  # the worker goes on with the next scene


def test_a_siconos_run_listens_on_no_port():
    """While a run goes on, no process of this test's tree listens on a TCP port; the same
    check finds a child that does (so the check can fail)."""
    scene = _block(0.25, 1.0, {"type": "free", "theta0_rad": 0.1}, 3.0)
    holder: dict = {}
    thread = threading.Thread(target=lambda: holder.update(r=SiconosSolver(warm=False).run(scene)))
    thread.start()
    seen, samples = {}, 0
    while thread.is_alive():
        seen.update(listening_of_tree(os.getpid()))
        samples += 1
        time.sleep(0.05)
    thread.join()
    assert holder["r"].ok and samples > 3 and not seen
    server = subprocess.Popen(
        [sys.executable, "-m", "http.server", "0", "--bind", "127.0.0.1"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        deadline = time.monotonic() + 60
        found: dict = {}
        while not found and time.monotonic() < deadline:
            found = listening_of_tree(os.getpid())
            time.sleep(0.05)
        assert found
    finally:
        server.kill()
        server.wait()


@pytest.mark.parametrize(
    ("options", "field"),
    [
        ({"dt_factor": 0.0}, "dt_factor"),
        ({"dt_factor": 1.5}, "dt_factor"),
        ({"dt_s": -1e-3}, "dt_s"),
        ({"solver_tol": 1.0}, "solver_tol"),
        ({"newton_max_iter": 0}, "newton_max_iter"),
        ({"restitution": 2.0}, "restitution"),
        ({"timeout_s": 0}, "timeout_s"),
        ({"stem": "x"}, "stem"),
    ],
)
def test_bad_options_are_refused_naming_the_field(options, field):
    with pytest.raises(InputError) as err:
        make_solver("siconos", **options)
    assert err.value.field == field


def test_a_target_mu_it_cannot_reach_is_refused_in_one_line():
    """A matched calibration asks for the paper's experimental mu (specimen 2, 0.973): the
    model's own (e = 0) is about 0.96; refused with the reachable range, before any run."""
    scene = load_scene(EXAMPLES / "specimen2_record21.toml")
    with pytest.raises(InputError) as err:
        SiconosSolver().run(scene)
    assert err.value.field == "contact.calibration"
    assert "reachable range" in str(err.value) and "\n" not in str(err.value)


def test_the_example_runs_with_the_geometrys_restitution_recorded():
    """``examples/specimen1_free.toml`` (paper calibration, experimental alpha, p, mu = 0.936):
    Siconos runs the model's own restitution and says so beside the scene's mu."""
    scene = load_scene(EXAMPLES / "specimen1_free.toml")
    d = scene.to_dict()
    d["duration_s"] = 0.5
    result = SiconosSolver().run(scene_from_dict(d, base_dir=Path(EXAMPLES)))
    assert result.ok
    own = model_restitution(SiconosSolver().model(scene).bodies[0])
    assert result.meta.extra["mu_model"]["specimen1"] == pytest.approx(own)
    assert result.meta.extra["mu_scene"]["specimen1"] == 0.936 and "mu_note" in result.meta.extra


def _short_free_scene(folder: Path, duration_s: float = 0.5) -> Path:
    """``examples/specimen1_free.toml`` cut to ``duration_s`` (scene mu 0.936, paper calibration)."""
    text = (EXAMPLES / "specimen1_free.toml").read_text()
    path = folder / "s1.toml"
    path.write_text(text.replace("duration_s = 4.0", f"duration_s = {duration_s}"))
    return path


def test_run_and_compare_print_that_siconos_runs_the_models_own_mu(tmp_path, capsys):
    """The console says, in one line, that Siconos's effective mu is the model's own (mu_model),
    not the scene's 0.936 (the note was only in the JSON)."""
    from rockyade.cli import main

    scene = _short_free_scene(tmp_path)
    own = model_restitution(SiconosSolver().model(load_scene(scene)).bodies[0])
    assert main(["run", str(scene), "--solver", "siconos"]) == 0
    notes = [ln for ln in capsys.readouterr().out.splitlines() if "note:" in ln]
    assert len(notes) == 1 and f"(mu_model): specimen1 {own:.4g} (scene mu 0.936)" in notes[0], notes
    code = main(["compare", str(scene), "--solvers", "housner,siconos", "--no-dt-check", "--out", str(tmp_path / "c")])
    notes = [ln for ln in capsys.readouterr().out.splitlines() if "note:" in ln]
    assert code == 0 and len(notes) == 1 and f"specimen1 {own:.4g}" in notes[0], notes


def test_worker_files_are_kept_only_after_a_failure_each_under_its_own_dt(tmp_path, monkeypatch, capsys):
    """A completed ``run --out`` leaves only the result beside it and nothing in the temporary
    folder (its worker files used to sit beside the result); a failed run's files go to the
    result's folder, named with the dt_factor, so runs at dt and dt/2 keep a log each (they
    used to share the scene-hash name, the second overwriting the first)."""
    import tempfile

    from rockyade.cli import main

    scratch = tmp_path / "tmp"
    scratch.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(scratch))
    out = tmp_path / "x"
    assert main(["run", str(_short_free_scene(tmp_path)), "--solver", "siconos", "--out", str(out / "s1.csv")]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["s1.csv", "s1.json"] and not list(scratch.iterdir())
    data = stack(widths_m=[0.4, 0.35], heights_m=0.5, motion=rest_motion(), duration_s=0.3, sample_dt_s=0.01)
    logs = []
    for factor in (1.0, 0.5):
        result = SiconosSolver(solver_max_iter=1, dt_factor=factor).keeping_files(out, "bad").run(scene_from_dict(data))
        assert not result.ok
        logs.append(Path(result.meta.log_path or ""))
    assert [p.name for p in logs] == ["bad_dt1.siconos.log", "bad_dt0.5.siconos.log"]
    assert all(p.parent == out.resolve() and p.is_file() for p in logs) and not list(scratch.iterdir())


def test_an_interrupted_run_leaves_no_files(tmp_path):
    """Ctrl-C (SIGINT) in the middle of a run: its private folder (the scene data, the empty log)
    is removed, and nothing goes to the folder that keeps a failed run's files."""
    import signal

    scratch, out = tmp_path / "tmp", tmp_path / "out"
    scratch.mkdir()
    scene = _block(0.25, 1.0, {"type": "free", "theta0_rad": 0.1}, 10_000.0, sample_dt=0.01)
    data = json.dumps(scene.to_dict())
    code = (
        "import json\nfrom rockyade.scene import scene_from_dict\nfrom rockyade.solvers.siconos import SiconosSolver\n"
        f"scene = scene_from_dict(json.loads({data!r}))\n"
        f"SiconosSolver().keeping_files({str(out)!r}, 'k').run(scene)\n"
    )
    env = {**os.environ, "TMPDIR": str(scratch), "PYTHONPATH": str(Path(__file__).resolve().parents[1])}
    proc = subprocess.Popen(
        [sys.executable, "-c", code], env=env, stderr=subprocess.PIPE, text=True, preexec_fn=sigint_default
    )
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and not list(scratch.glob("rockyade-siconos-*/*.siconos.json")):
        time.sleep(0.05)
    assert list(scratch.glob("rockyade-siconos-*/*.siconos.json")), "the run never started"
    time.sleep(1.0)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode != 0 and "KeyboardInterrupt" in err, err
    assert not list(scratch.iterdir()) and not out.exists()


def test_the_page_quotes_what_the_run_prints_and_the_version_is_the_packages(capsys):
    """docs/siconos.md shows the lines ``rockyade run examples/specimen1_free.toml --solver
    siconos`` prints (it showed 0.915 for 0.91437), and the Result names the Debian package's
    version (4.4.0+dfsg-2), not only the module's own label (4.5.0)."""
    from rockyade.cli import main

    from .conftest import ROOT

    assert main(["run", str(EXAMPLES / "specimen1_free.toml"), "--solver", "siconos"]) == 0
    printed = [ln.strip() for ln in capsys.readouterr().out.splitlines()]
    quoted = [ln.strip() for ln in (ROOT / "docs/siconos.md").read_text().splitlines() if ln.startswith("    ")]
    for start in ("specimen1: max |theta|", "note: "):
        line = next(ln for ln in printed if ln.startswith(start))
        assert line in quoted, line
    package = siconos_backend.package_version()
    if package is not None:  # dpkg knows the installation
        result = SiconosSolver().run(_block(0.25, 1.0, {"type": "free", "theta0_rad": 0.1}, 0.1))
        assert result.meta.version.startswith(f"Siconos {package} (Debian python3-siconos")
