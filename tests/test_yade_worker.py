"""YADE kept warm (rockyade.io.warm_program, through rockyade.yade.backend), with YADE really
running: the same results as one process per run, a crash or a timeout costs one scene, no
port, nothing left behind, no write through a link, a full disk named and cleaned up."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import rockyade
from rockyade.calibration.model_stage import calibrated_model
from rockyade.result import Result
from rockyade.runner import Executor, solve_scenes
from rockyade.scene import load_scene, scene_from_dict
from rockyade.solvers.yade import YadeSolver
from rockyade.yade import backend as yade_backend

from .conftest import EXAMPLES
from .processes import alive, cmdline, descendants, listening_of_tree, require_yade

pytestmark = pytest.mark.yade


@pytest.fixture(scope="module", autouse=True)
def _yade_present():
    require_yade()


def _scene(example: str, duration: float, **top):
    d = load_scene(EXAMPLES / example).to_dict()
    d.update(duration_s=duration, **top)
    return scene_from_dict(d)


def _serving() -> set[int]:
    """This process's YADE workers (not the Siconos workers a test run before may have left warm)."""
    return {p for p in descendants(os.getpid()) if "--serve" in cmdline(p) and "yade/driver.py" in cmdline(p)}


def _same(a, b) -> None:
    assert a.ok and b.ok, (a.meta.failure_reason, b.meta.failure_reason)
    assert a.frame.equals(b.frame)  # bit for bit
    for key in ("status", "overturn_time_s", "iterations", "dt_s", "overturn_times_s"):
        assert a.meta.to_dict().get(key) == b.meta.to_dict().get(key), key


def test_a_warm_worker_gives_the_results_of_one_process_per_run_bit_for_bit():
    """Scenes that set different materials, engines (a base motion or none), time steps and
    block counts, in a row in one worker, against a process of their own each. The free and
    harmonic runs are short (each runs three times): what is compared is every sample and the
    metadata, whatever the length (0.3, 0.6 and 0.4 s against 0.6, 1.5 and 1.0 s before)."""
    scenes = [
        _scene("biblock_free.toml", 0.3),
        _scene("specimen1_harmonic.toml", 0.6, sample_dt_s=0.002),
        _scene("specimen3_free.toml", 0.4),
        _scene("specimen1_pulse.toml", 1.0),
    ]
    cold = [YadeSolver(warm=False).run(s) for s in scenes]
    order = [1, 0, 2, 3, 1, 2, 0]
    warm = [YadeSolver().run(scenes[i]) for i in order]
    for i, result in zip(order, warm, strict=True):
        _same(result, cold[i])
    assert len(_serving()) == 1  # one worker ran them all


def test_a_scene_that_raises_or_crashes_costs_only_that_scene(tmp_path, monkeypatch):
    good = _scene("specimen3_free.toml", 0.5)
    reference = YadeSolver().run(good)  # a warm worker's result is one process's, bit for bit (above)
    assert reference.ok
    real = yade_backend.scene_payload

    def broken(model):
        payload = real(model)
        del payload["bodies"][0]["sphere_copies"]
        return payload

    monkeypatch.setattr(yade_backend, "scene_payload", broken)
    bad = YadeSolver(workdir=tmp_path, stem="bad").run(good)
    monkeypatch.undo()
    assert bad.status == "failed" and "exited with code 1" in bad.meta.failure_reason
    assert "KeyError" in bad.meta.failure_reason and "Traceback" in (tmp_path / "bad.yade.log").read_text()
    _same(YadeSolver().run(good), reference)  # a fresh worker takes the next scene

    # a crash: the worker killed by a signal in the middle of a scene
    long = _scene("specimen1_free.toml", 3600.0, sample_dt_s=0.01)
    holder: dict = {}
    thread = threading.Thread(target=lambda: holder.update(r=YadeSolver(workdir=tmp_path, stem="crash").run(long)))
    before = _serving()
    thread.start()
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and not (_serving() - before):
        time.sleep(0.05)
    (victim,) = _serving() - before
    time.sleep(1.0)
    os.kill(victim, signal.SIGSEGV)
    thread.join(60)
    crashed = holder["r"]
    assert crashed.status == "failed" and "exited with code -11" in crashed.meta.failure_reason
    assert not alive(victim)
    _same(YadeSolver().run(good), reference)


def test_each_scene_has_its_own_timeout_and_a_timed_out_run_keeps_its_samples(tmp_path):
    """A run stopped at its timeout (the driver stops it at the deadline): status failed, never
    complete, with the samples it recorded marked partial (the same, bit for bit, as the start
    of a complete run), read back from its files as such; the warm worker takes the next scene
    with a fresh limit."""
    short = _scene("specimen3_free.toml", 0.5)
    assert YadeSolver().run(short).ok
    (pid,) = _serving()
    start = time.monotonic()
    long = _scene("specimen1_free.toml", 3600.0, sample_dt_s=0.01)  # an hour: no machine finishes it in 1 s
    slow = YadeSolver(workdir=tmp_path, stem="slow", timeout_s=1.0).run(long)
    assert time.monotonic() - start < 20
    assert slow.status == "failed" and not slow.ok
    assert slow.meta.failure_reason.startswith("timeout: YADE did not finish within 1 s")
    n = slow.meta.partial_samples
    assert slow.meta.partial is True and 0 < n == len(slow.frame) < calibrated_model(long).n_samples
    assert slow.meta.overturn_time_s is None
    assert not list(tmp_path.glob("*.part"))
    complete = YadeSolver().run(_scene("specimen1_free.toml", 1.0, sample_dt_s=0.01))  # in the same worker
    m = min(n, len(complete.frame))
    for column in ("theta_rad", "omega_rad_s", "x_m", "y_m"):
        assert np.array_equal(slow.frame[column].to_numpy()[:m], complete.frame[column].to_numpy()[:m]), column
    slow.write(tmp_path / "slow.csv")
    back = Result.read(tmp_path / "slow.csv")
    assert back.status == "failed" and back.meta.partial is True and len(back.frame) == n
    again = YadeSolver(timeout_s=30.0).run(short)  # the same worker, a fresh limit
    assert again.ok and _serving() == {pid}


def test_a_killed_yade_run_keeps_the_samples_it_flushed(tmp_path, monkeypatch):
    """A worker killed from outside in the middle of a scene (a hard kill: nothing of the
    driver runs) after it flushed its samples: the run fails naming the signal, keeps the
    samples of the last flush marked partial, and that flushed file is whole (written to a
    ``.part`` file and renamed: a kill never leaves a truncated output)."""
    monkeypatch.setattr(yade_backend, "FLUSH_PERIOD_S", 0.3)
    long = _scene("specimen1_free.toml", 3600.0, sample_dt_s=0.01)
    holder: dict = {}
    thread = threading.Thread(target=lambda: holder.update(r=YadeSolver(workdir=tmp_path, stem="k").run(long)))
    before = _serving()
    thread.start()
    running = tmp_path / "k.running.yade.npz"  # the run's own name until it ends
    npz = tmp_path / "k.yade.npz"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and not ((_serving() - before) and running.is_file()):
        time.sleep(0.05)
    (victim,) = _serving() - before
    time.sleep(0.5)
    os.kill(victim, signal.SIGKILL)
    thread.join(60)
    killed = holder["r"]
    assert killed.status == "failed" and "exited with code -9" in killed.meta.failure_reason
    n = killed.meta.partial_samples
    assert killed.meta.partial is True and 0 < n == len(killed.frame) < calibrated_model(long).n_samples
    with np.load(npz, allow_pickle=False) as data:
        meta = json.loads(str(data["meta"]))
        assert meta["complete"] is False and meta["status"] == "running" and meta["n_filled"] == n
        assert data["ang"].shape[0] == n
    assert not list(tmp_path.glob("*.part"))


def test_threads_each_keep_a_worker_and_close_it_when_they_end():
    before = _serving()
    scenes = [_scene("specimen3_free.toml", 0.4, motion={"type": "free", "theta0_rad": t}) for t in (0.02, 0.03, 0.04)]
    results = solve_scenes(YadeSolver(), scenes, executor=Executor("threads", 2))
    assert all(r.ok for r in results)
    deadline = time.monotonic() + 10
    while _serving() != before and time.monotonic() < deadline:
        time.sleep(0.1)
    assert _serving() == before  # the pool's threads ended: their workers were closed


RUN_TWICE = """
import sys, time
from rockyade.scene import load_scene, scene_from_dict
from rockyade.solvers.yade import YadeSolver
d = load_scene(sys.argv[1]).to_dict()
d["duration_s"] = float(sys.argv[2])
for _ in range(2):
    assert YadeSolver().run(scene_from_dict(d)).ok
print("done", flush=True)
time.sleep(float(sys.argv[3]))
"""


def test_a_warm_worker_listens_on_no_port_and_dies_with_its_parent():
    import select

    proc = subprocess.Popen(
        [sys.executable, "-c", RUN_TWICE, str(EXAMPLES / "specimen1_free.toml"), "3.0", "60"],
        stdout=subprocess.PIPE,
        text=True,
    )
    assert proc.stdout is not None
    try:
        seen: dict = {}
        polls = 0
        deadline = time.monotonic() + 240
        while proc.poll() is None and time.monotonic() < deadline:
            seen |= listening_of_tree(proc.pid)
            polls += 1
            if select.select([proc.stdout], [], [], 0.05)[0]:
                break
        assert proc.stdout.readline().strip() == "done"
        assert polls > 10 and not seen
        workers = {p for p in descendants(proc.pid) if "--serve" in cmdline(p)}
        assert len(workers) == 1 and all(alive(p) for p in workers)  # one worker ran both, and waits, warm
        proc.kill()
        proc.wait()
        deadline = time.monotonic() + 10
        while any(alive(p) for p in workers) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not any(alive(p) for p in workers), "a YADE worker outlived the process that started it"
    finally:
        proc.kill()
        proc.wait()


def test_the_log_is_never_written_through_a_link(tmp_path, monkeypatch):
    """A link planted where YADE's log goes, before the run and again whenever rockyade
    removes the old log (an attacker winning the race between removing and opening): the
    file it points to is never written. It was opened with a plain open(..., "w")."""
    import pathlib

    victim = tmp_path / "victim.txt"
    victim.write_text("keep me")
    work = tmp_path / "work"
    work.mkdir()
    log = work / "x.yade.log"
    log.symlink_to(victim)
    real_unlink = pathlib.Path.unlink

    def unlink_and_plant(self, missing_ok=False):
        real_unlink(self, missing_ok=missing_ok)
        if self.name == "x.yade.log":
            self.symlink_to(victim)

    monkeypatch.setattr(pathlib.Path, "unlink", unlink_and_plant)
    result = YadeSolver(workdir=work, stem="x").run(_scene("specimen3_free.toml", 0.3))
    monkeypatch.undo()
    assert result.ok
    assert victim.read_text() == "keep me"
    assert not log.is_symlink() and log.is_file()


# ---------------------------------------------------------------------- a private /tmp


def _namespace_or_skip() -> None:
    probe = subprocess.run(["unshare", "-Urm", "true"], capture_output=True)
    if probe.returncode != 0:
        pytest.skip("cannot mount a tmpfs here (no user namespaces)")


def test_yade_runs_leave_nothing_in_the_temporary_folder(tmp_path):
    """/tmp a fresh tmpfs of its own: after YADE runs (one in its own process, two warm,
    one that times out) it holds only the TMPDIR given, empty. Every run used to leave an
    empty /tmp/yade-XXXXXX (YADE's, made at import whatever TMPDIR says)."""
    _namespace_or_skip()
    d = load_scene(EXAMPLES / "specimen3_free.toml").to_dict()
    d["duration_s"] = 0.4
    code = (
        "import json, sys\nfrom rockyade.scene import scene_from_dict\nfrom rockyade.solvers.yade import YadeSolver\n"
        f"d = json.loads({json.dumps(d)!r})\ns = scene_from_dict(d)\n"
        "long = scene_from_dict({**d, 'duration_s': 3600.0, 'sample_dt_s': 0.01})\n"
        "r = YadeSolver(timeout_s=0.01, workdir='/tmp/kept0').run(long)\n"  # shorter than YADE's start-up
        "assert r.meta.failure_reason.startswith('timeout'), r.meta\n"
        "assert YadeSolver(warm=False).run(s).ok and YadeSolver().run(s).ok and YadeSolver().run(s).ok\n"
        "r = YadeSolver(timeout_s=0.5, workdir='/tmp/kept').run(long)\n"  # in the warm worker: stopped mid-run
        "assert r.meta.failure_reason.startswith('timeout'), r.meta\n"
    )
    # a checkout or a virtual environment under /tmp (a fresh clone in /tmp/fresh) stays
    # visible: the old /tmp is bound to /var/tmp (in this mount namespace only) and those
    # folders bound back into the new, empty /tmp
    needed = sorted(
        {
            Path(where).resolve().relative_to("/tmp").parts[0]
            for where in (sys.prefix, Path(rockyade.__file__).parent)
            if Path(where).resolve().is_relative_to("/tmp")
        }
    )
    binds = "".join(f"mkdir /tmp/{name} && mount --bind /var/tmp/{name} /tmp/{name} && " for name in needed)
    script = (
        f"mount --bind /tmp /var/tmp && mount -t tmpfs tmpfs /tmp && {binds}mkdir /tmp/ours && "
        f'TMPDIR=/tmp/ours {sys.executable} -c "$0" && echo RAN && ls -A /tmp && echo -- && ls -A /tmp/ours'
    )
    proc = subprocess.run(["unshare", "-Urm", "sh", "-c", script, code], capture_output=True, text=True, timeout=300)
    assert "RAN" in proc.stdout, proc.stdout + proc.stderr
    in_tmp, in_ours = proc.stdout.split("RAN", 1)[1].split("--")
    # kept: the workdir asked for (the timed-out run's log); nothing of YADE's
    assert sorted(in_tmp.split()) == sorted(["kept", "kept0", "ours", *needed]), in_tmp
    assert in_ours.split() == [], in_ours


def test_a_full_disk_names_the_file_leaves_no_partial_output_and_resume_goes_on(tmp_path):
    """YADE's output on a full disk (a small tmpfs): the run fails naming the file, no
    ``.yade.npz.part`` is left, and once there is room ``--resume`` runs it. It used to leave
    the partial file, and --resume failed until it was removed by hand."""
    _namespace_or_skip()
    disk = tmp_path / "disk"
    disk.mkdir()
    d = load_scene(EXAMPLES / "specimen3_free.toml").to_dict()
    d.update(duration_s=2.0, sample_dt_s=0.001)  # its output, about 180 kB, cannot fit in 96 kB
    (tmp_path / "s.json").write_text(json.dumps(d))
    (tmp_path / "study.toml").write_text(
        f'solvers = ["yade"]\nsave_histories = false\n[base]\nfile = {json.dumps(str(tmp_path / "s.json"))}\n'
    )
    batch = f"{sys.executable} -m rockyade batch {tmp_path / 'study.toml'} --out {disk}/out --quiet --workers 1"
    script = (
        f"mount -t tmpfs -o size=96k tmpfs {disk} && {batch}; echo EXIT=$?; "
        f"find {disk} -name '*.part' -o -name '.*.tmp'; echo FOUND; "
        f"mount -o remount,size=64m {disk} && {batch} --resume; echo EXIT2=$?; cat {disk}/out/summary.csv"
    )
    proc = subprocess.run(["unshare", "-Urm", "sh", "-c", script], capture_output=True, text=True, timeout=600)
    out = proc.stdout
    assert "EXIT=1" in out, out + proc.stderr
    first = out.split("EXIT=1", 1)[0]
    assert "disk full" in first and ".yade.npz" in first, first
    assert out.split("EXIT=1", 1)[1].split("FOUND", 1)[0].split() == []  # no partial file, no temporary
    assert "EXIT2=0" in out, out + proc.stderr
    assert "completed" in out.split("EXIT2=0", 1)[1]
    assert "Traceback" not in proc.stderr


def _yade_batch(folder, runs: int, duration_s: float, *extra: str) -> subprocess.Popen[str]:
    """`rockyade batch` of ``runs`` YADE runs of specimen 1 (harmonic, then free rocking until
    ``duration_s``) started from ``folder`` as a terminal would (its own session)."""
    scene = (EXAMPLES / "specimen1_harmonic.toml").read_text()
    scene = scene.replace("duration_s = 12.0", f"duration_s = {duration_s}")
    (folder / "scene.toml").write_text(scene)
    amplitudes = ", ".join(f"{4.0 + 0.1 * i:.1f}" for i in range(runs))
    (folder / "study.toml").write_text(
        'name = "warm"\nsolvers = ["yade"]\n[base]\nfile = "scene.toml"\n'
        f'[grid]\n"motion.amplitude_mm" = [{amplitudes}]\n'
    )
    return subprocess.Popen(
        [sys.executable, "-m", "rockyade", "batch", "study.toml", "--out", "out", "--quiet", *extra],
        cwd=folder,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


@pytest.mark.parametrize(
    ("executor", "presses"), [("local", 2), ("dask", 2), ("local", 1)], ids=["local-twice", "dask-twice", "local-once"]
)
def test_ctrl_c_in_a_batch_leaves_no_warm_yade_behind(tmp_path, executor, presses):
    """Ctrl-C (once: the running runs finish; twice: they stop at once) in a batch of YADE runs:
    the batch exits with 130 and none of its warm YADE workers (a session of their own, which
    the terminal's Ctrl-C does not reach) outlives it."""
    if executor == "dask":
        pytest.importorskip("dask")
    proc = _yade_batch(tmp_path, 4, 40.0 if presses == 2 else 4.0, "--workers", "2", "--executor", executor)
    try:
        deadline = time.monotonic() + 180
        yade: set[int] = set()
        while len(yade) < 2 and proc.poll() is None and time.monotonic() < deadline:
            yade = {p for p in descendants(proc.pid) if "--serve" in cmdline(p) and "yade/driver.py" in cmdline(p)}
            time.sleep(0.1)
        assert len(yade) == 2, "two warm YADE workers"
        time.sleep(1.0)  # the runs are under way
        for press in range(presses):
            if press:
                time.sleep(0.3)
            os.killpg(proc.pid, signal.SIGINT)
        _stdout, stderr = proc.communicate(timeout=120)
        assert proc.returncode == 130 and "Traceback" not in stderr, stderr
        deadline = time.monotonic() + 10
        while any(alive(p) for p in yade) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not any(alive(p) for p in yade), "a warm YADE worker outlived its batch"
        summary = (tmp_path / "out" / "summary.csv").read_text()
        assert ("stopped by Ctrl-C" in summary) == (presses == 2)
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
