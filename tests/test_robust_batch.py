"""Batches under stress, with real processes and real signals: Ctrl-C once and twice, a
SIGKILLed parent and resume, no listening socket with Dask, a full disk, one writer."""

from __future__ import annotations

import errno
import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path
from typing import NamedTuple

import pandas as pd
import pytest

from rockyade.batch import comparable, expand, run_study_tasks
from rockyade.cli import main
from rockyade.errors import BatchInterruptedError, InputError
from rockyade.io.locking import output_lock
from rockyade.result import Result
from rockyade.scene import load_scene

from .conftest import EXAMPLES
from .processes import alive, descendants

# ---------------------------------------------------------------------- helpers


def _study(folder: Path, duration_s: float, runs: int, sample_dt: float = 0.01) -> Path:
    """A study of ``runs`` reference-DEM runs of specimen 3 rocking freely for ``duration_s``."""
    scene = folder / "scene.toml"
    scene.write_text(
        (EXAMPLES / "specimen3_free.toml")
        .read_text()
        .replace("duration_s = 4.0", f"duration_s = {duration_s}")
        .replace("sample_dt_s = 0.001", f"sample_dt_s = {sample_dt}")
    )
    thetas = ", ".join(f"{0.02 + 0.005 * i:.3f}" for i in range(runs))
    study = folder / "study.toml"
    study.write_text(
        f'name = "stress"\nsolvers = ["reference"]\n[base]\nfile = "scene.toml"\n'
        f'[grid]\n"motion.theta0_rad" = [{thetas}]\n'
    )
    return study


def _batch(folder: Path, *extra: str) -> subprocess.Popen[str]:
    """`rockyade batch study.toml --out out` started from ``folder`` as a terminal would
    (its own session: Ctrl-C goes to its process group)."""
    return subprocess.Popen(
        [sys.executable, "-m", "rockyade", "batch", "study.toml", "--out", "out", "--quiet", *extra],
        cwd=folder,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


def _wait_for(condition, timeout: float, what: str) -> None:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if condition():
            return
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


def _results(out: Path) -> list[Path]:
    return sorted((out / "runs").glob("*.json")) if (out / "runs").is_dir() else []


def _leftovers(out: Path) -> list[Path]:
    return [p for p in out.rglob(".*") if p.name.endswith((".tmp", ".pending", ".lock"))]


def _resume(folder: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> int:
    """`rockyade batch study.toml --out out --quiet --resume` run in this process (the same
    ``main``; what the test stops is the real process before it, and a second process would
    only add its start-up)."""
    capsys.readouterr()
    monkeypatch.chdir(folder)
    return main(["batch", "study.toml", "--out", "out", "--quiet", "--resume"])


class _Stat(NamedTuple):
    pgrp: int
    cpu_s: float


def _stat(pid: int, task: int | None = None) -> _Stat:
    """A process's (or one of its threads') process group and CPU seconds, from /proc (a process
    gone: no group, no CPU)."""
    where = f"/proc/{pid}" if task is None else f"/proc/{pid}/task/{task}"
    try:
        fields = Path(f"{where}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return _Stat(-1, 0.0)
    return _Stat(int(fields[2]), (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK"))


def _threads_cpu_s(pid: int) -> list[float]:
    """The CPU seconds of each thread of ``pid`` but its main thread."""
    try:
        tasks = [int(t) for t in os.listdir(f"/proc/{pid}/task")]
    except OSError:
        return []
    return [_stat(pid, t).cpu_s for t in tasks if t != pid]


def _workers_of(proc: subprocess.Popen[str], count: int) -> set[int]:
    _wait_for(lambda: len(descendants(proc.pid)) >= count, 120, f"{count} worker processes")
    return descendants(proc.pid)


# ---------------------------------------------------------------------- Ctrl-C


@pytest.mark.slow
def test_first_ctrl_c_lets_running_runs_finish_and_writes_the_summary(tmp_path, monkeypatch, capsys):
    # 6 runs: at most 2 are in flight (rockyade.runner.local), so at Ctrl-C, one or two ended,
    # two running and two or more not started
    _study(tmp_path, duration_s=100.0, runs=6)  # runs of ~0.5 s CPU
    proc = _batch(tmp_path, "--workers", "2")
    out = tmp_path / "out"
    _wait_for(lambda: len(_results(out)) >= 1, 300, "a first finished run")
    workers = descendants(proc.pid)
    os.killpg(proc.pid, signal.SIGINT)  # what the terminal does on Ctrl-C
    _stdout, stderr = proc.communicate(timeout=300)
    assert proc.returncode == 130, stderr
    assert "Traceback" not in stderr
    assert "Ctrl-C: no new run starts; waiting for the running runs to finish" in stderr
    assert "rockyade: interrupted:" in stderr and "--resume" in stderr
    summary = pd.read_csv(out / "summary.csv")
    assert list(summary["index"]) == list(range(6))
    finished = summary[summary.status == "completed"]
    unfinished = summary[summary.status == "unfinished"]
    assert len(finished) >= 1 and len(unfinished) >= 1 and len(finished) + len(unfinished) == 6
    assert (unfinished.failure_reason == "not started: Ctrl-C").all()
    assert sorted(p.stem for p in _results(out)) == sorted(finished.run)  # running runs were let finish
    for run in finished.run:
        assert Result.read(out / "runs" / f"{run}.csv").status == "completed"
    _wait_for(lambda: not any(alive(p) for p in workers), 30, "the workers to end")
    assert not _leftovers(out)

    stamps = {p.name: p.stat().st_mtime_ns for p in _results(out)}
    assert _resume(tmp_path, monkeypatch, capsys) == 0, capsys.readouterr().err
    summary = pd.read_csv(out / "summary.csv")
    assert (summary.status == "completed").all() and len(summary) == 6 and summary.run.is_unique
    for name, stamp in stamps.items():
        assert (out / "runs" / name).stat().st_mtime_ns == stamp  # not run twice


@pytest.mark.parametrize("executor", ["local", "dask"])
@pytest.mark.slow
def test_second_ctrl_c_stops_at_once_and_no_worker_survives(tmp_path, executor):
    if executor == "dask":
        pytest.importorskip("dask")
    _study(tmp_path, duration_s=4000.0, runs=4, sample_dt=0.05)  # runs of ~20 s
    proc = _batch(tmp_path, "--workers", "2", "--executor", executor)
    # the runs under way (seen in /proc, not after a sleep): two workers that set themselves up
    # (Ctrl-C ignored, a process group of their own) and run, or two threads of the batch running
    if executor == "local":
        workers = _workers_of(proc, 2)
        _wait_for(
            lambda: sum(_stat(pid).pgrp == pid and _stat(pid).cpu_s > 0.1 for pid in workers) >= 2, 120, "two runs"
        )
    else:  # the runs are threads of the batch process
        workers = set()
        _wait_for(lambda: sum(cpu > 0.1 for cpu in _threads_cpu_s(proc.pid)) >= 2, 120, "two runs")
    os.killpg(proc.pid, signal.SIGINT)
    assert proc.stderr is not None
    said = [proc.stderr.readline()]  # the second press once the first was handled (its line)
    while said[-1] and "Ctrl-C: no new run starts" not in said[-1]:
        said.append(proc.stderr.readline())
    os.killpg(proc.pid, signal.SIGINT)
    _stdout, rest = proc.communicate(timeout=60)
    stderr = "".join(said) + rest
    assert not _results(tmp_path / "out")  # the running runs (~20 s each) were stopped, not let finish
    assert proc.returncode == 130 and "Traceback" not in stderr
    assert "Ctrl-C again: stopping the running runs now" in stderr
    summary = pd.read_csv(tmp_path / "out" / "summary.csv")
    assert len(summary) == 4 and (summary.status == "unfinished").all()
    assert set(summary.failure_reason) == {"stopped by Ctrl-C", "not started: Ctrl-C"}
    assert (summary.failure_reason == "stopped by Ctrl-C").sum() == 2  # the two running runs
    _wait_for(lambda: not any(alive(p) for p in workers), 10, "the workers to end")
    assert not _leftovers(tmp_path / "out")


@pytest.mark.slow
def test_sigkilled_parent_takes_its_workers_and_resume_loses_nothing(tmp_path, monkeypatch, capsys):
    # 5 runs: killed after two ended, with at most two running (rockyade.runner.local), so the
    # resume has lost runs to run again and at least one that never started
    _study(tmp_path, duration_s=100.0, runs=5)
    proc = _batch(tmp_path, "--workers", "2")
    out = tmp_path / "out"
    _wait_for(lambda: len(_results(out)) >= 2, 300, "two finished runs")
    workers = descendants(proc.pid)
    assert workers
    proc.kill()  # SIGKILL: no handler, no clean-up
    proc.communicate(timeout=30)
    _wait_for(lambda: not any(alive(p) for p in workers), 10, "the orphaned workers to die")
    done_before = {p.name: p.stat().st_mtime_ns for p in _results(out)}

    assert _resume(tmp_path, monkeypatch, capsys) == 0, capsys.readouterr().err
    summary = pd.read_csv(out / "summary.csv")
    assert list(summary["index"]) == list(range(5)) and summary.run.is_unique
    assert (summary.status == "completed").all()
    assert len(_results(out)) == 5 and len(list((out / "runs").glob("*.csv"))) == 5
    for run in summary.run:
        data = json.loads((out / "runs" / f"{run}.json").read_text())
        assert data["summary"]["run"] == run and Result.read(out / "runs" / f"{run}.csv").ok
    for name, stamp in done_before.items():
        assert (out / "runs" / name).stat().st_mtime_ns == stamp
    assert not _leftovers(out)


# ---------------------------------------------------------------------- Dask


def _listening_inodes() -> set[str]:
    inodes = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        with open(table) as fh:
            next(fh)
            for line in fh:
                fields = line.split()
                if fields[3] == "0A":  # TCP_LISTEN
                    inodes.add(fields[9])
    return inodes


def _socket_inodes(pids: set[int]) -> set[str]:
    inodes = set()
    for pid in pids:
        try:
            fds = os.listdir(f"/proc/{pid}/fd")
        except OSError:
            continue
        for fd in fds:
            try:
                target = os.readlink(f"/proc/{pid}/fd/{fd}")
            except OSError:
                continue
            if target.startswith("socket:["):
                inodes.add(target[8:-1])
    return inodes


def _listening_sockets_of_tree(pid: int) -> set[str]:
    """The listening TCP sockets held by ``pid`` or a process below it. The kernel's tables are
    read only when the tree holds a socket at all (reading them costs ~10 ms, a third of a core
    at the callers' 20 ms polling; the answer is the same)."""
    held = _socket_inodes({pid, *descendants(pid)})
    return _listening_inodes() & held if held else set()


def test_the_socket_poller_sees_a_listening_socket():
    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen()
        assert _listening_sockets_of_tree(os.getpid())


@pytest.mark.slow
def test_dask_batch_without_scheduler_opens_no_listening_socket(tmp_path):
    pytest.importorskip("dask")
    runs = 4  # two at a time on Dask's two threads, twice
    _study(tmp_path, duration_s=30.0, runs=runs)
    proc = _batch(tmp_path, "--executor", "dask", "--workers", "2")
    seen: set[str] = set()
    while_running = 0  # looks taken while Dask's runs were under way (its runs folder there)
    while proc.poll() is None:
        running = (tmp_path / "out" / "runs").is_dir()
        seen |= _listening_sockets_of_tree(proc.pid)
        while_running += running and proc.poll() is None
        time.sleep(0.02)
    _stdout, stderr = proc.communicate()
    assert proc.returncode == 0, stderr
    assert while_running >= 1 and not seen
    summary = pd.read_csv(tmp_path / "out" / "summary.csv")
    assert (summary.status == "completed").all() and len(summary) == runs


def _tasks(out: Path, duration: float = 1.0) -> list:
    base = load_scene(EXAMPLES / "specimen3_free.toml").to_dict()
    base["duration_s"] = duration
    grid = {"motion.theta0_rad": [0.03, 0.06], "blocks.0.p_rad_s": [3.5, 3.61]}
    return expand([("specimen3", base)], grid, ["reference", "housner"], save_history=True)


def test_in_process_dask_summary_equals_local(tmp_path):
    pytest.importorskip("dask")
    local = run_study_tasks(_tasks(tmp_path / "a"), tmp_path / "a", workers=2, progress=False)
    dask = run_study_tasks(_tasks(tmp_path / "b"), tmp_path / "b", executor="dask", workers=2, progress=False)
    pd.testing.assert_frame_equal(comparable(local), comparable(dask))


def test_unreachable_scheduler_is_an_error_naming_it(tmp_path):
    pytest.importorskip("distributed")
    with pytest.raises(InputError) as info:
        run_study_tasks(
            _tasks(tmp_path)[:1],
            tmp_path,
            executor="dask",
            scheduler="tcp://127.0.0.1:9",
            scheduler_timeout_s=1.0,
            progress=False,
        )
    assert info.value.field == "scheduler" and "no Dask scheduler answered" in str(info.value)


# ---------------------------------------------------------------------- disk, lock, cost


def test_full_disk_fails_one_run_and_the_batch_goes_on(tmp_path, monkeypatch):
    tasks = _tasks(tmp_path)
    real_fsync = os.fsync
    victim = tasks[1]

    victim_hash = victim.scene_hash

    def fsync(fd: int) -> None:
        path = os.readlink(f"/proc/self/fd/{fd}")
        if victim_hash in path and victim.solver.name in path:
            raise OSError(errno.ENOSPC, "No space left on device")
        real_fsync(fd)

    monkeypatch.setattr(os, "fsync", fsync)  # the forked workers inherit it
    summary = run_study_tasks(tasks, tmp_path, workers=1, progress=False)
    failed = summary[summary.status == "failed"]
    assert list(failed["index"]) == [1]
    assert "cannot write the result" in failed.failure_reason.iloc[0] and "disk full" in failed.failure_reason.iloc[0]
    assert (summary.drop(index=1).status == "completed").all()
    assert not _leftovers(tmp_path)
    assert not list((tmp_path / "runs").glob(f"{victim_hash}_{victim.solver.name}.*"))


@pytest.mark.slow
def test_tiny_tmpfs_full_disk_is_a_clear_failure(tmp_path):
    """A real full disk: a 64 KiB tmpfs in a private mount namespace (skipped where it
    cannot be mounted)."""
    probe = subprocess.run(["unshare", "-Urm", "true"], capture_output=True)
    if probe.returncode != 0:
        pytest.skip("cannot mount a tmpfs here (no user namespaces)")
    disk = tmp_path / "disk"
    disk.mkdir()
    scene = EXAMPLES / "specimen1_free.toml"
    script = (
        f"mount -t tmpfs -o size=64k tmpfs {disk} && cd {disk} && "
        f"{sys.executable} -m rockyade run {scene} --out r.csv; "
        f"echo EXIT=$?; ls -A {disk}"
    )
    proc = subprocess.run(["unshare", "-Urm", "sh", "-c", script], capture_output=True, text=True, timeout=300)
    assert "EXIT=1" in proc.stdout, proc.stdout + proc.stderr
    assert "disk full" in proc.stderr and "Traceback" not in proc.stderr
    listing = proc.stdout.split("EXIT=1", 1)[1].split()
    assert listing == []  # no temporary file, no half result


def test_a_second_batch_into_the_same_output_is_refused(tmp_path):
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import sys, time\nfrom rockyade.io.locking import output_lock\n"
            "with output_lock(sys.argv[1]):\n    print('held', flush=True)\n    time.sleep(60)\n",
            str(tmp_path),
        ],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout is not None and holder.stdout.readline().strip() == "held"
        with pytest.raises(InputError) as info:
            run_study_tasks(_tasks(tmp_path)[:1], tmp_path, workers=1, progress=False)
        assert info.value.field == "out" and f"pid {holder.pid}" in str(info.value)
    finally:
        holder.kill()
        holder.wait()
    with output_lock(tmp_path):  # the kernel released the killed holder's lock
        pass


def test_a_batch_above_the_cost_limits_is_refused_before_any_run(tmp_path):
    base = load_scene(EXAMPLES / "specimen3_free.toml").to_dict()
    tasks = expand([("s", base)], {"contact.dt_s": [1e-5, 1e-8]}, ["reference"])
    with pytest.raises(InputError) as info:
        run_study_tasks(tasks, tmp_path, workers=1, progress=False)
    assert info.value.field == "allow_large" and "run 1 (base = s, contact.dt_s = 1e-08)" in str(info.value)
    assert not (tmp_path / "runs").exists()


def test_interrupted_error_reports_counts():
    exc = BatchInterruptedError(3, 5, "out/summary.csv")
    assert "3 run(s) finished, 5 unfinished; out/summary.csv lists them" in str(exc) and not exc.hard
