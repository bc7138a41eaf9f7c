"""A real Dask deployment: a scheduler and workers started with Dask's own commands
(``dask scheduler``, ``dask worker``) on the loopback interface, no dashboard; batches (the
command's ``main`` in the test's process) run against it. Nothing listens beyond 127.0.0.1; the summary equals a
local run's; a worker killed mid-study costs no run and duplicates none."""

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

import pandas as pd
import pytest

from rockyade.batch import comparable
from rockyade.cli import main
from rockyade.result import Result

from .conftest import EXAMPLES
from .processes import alive, descendants, listening_tcp, socket_inodes

distributed = pytest.importorskip("distributed")

DASK = str(Path(sys.executable).parent / "dask")
#: ``--no-dashboard`` alone still serves HTTP (health, metrics) on 0.0.0.0 (:8787 for the
#: scheduler): the address keeps that server on loopback, on a free port
NO_DASHBOARD = ("--no-dashboard", "--dashboard-address", "127.0.0.1:0")


def _wait_for(condition, timeout: float, what: str) -> None:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if condition():
            return
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


class Cluster:
    """``dask scheduler`` and ``workers`` ``dask worker`` processes (no nanny: one process
    each, so killing one kills the worker), all bound to 127.0.0.1 with no dashboard (their
    HTTP server on 127.0.0.1), run from a folder of their own (a relative path would land
    there)."""

    def __init__(self, folder: Path, workers: int) -> None:
        folder.mkdir()
        self.folder = folder
        file = folder / "scheduler.json"
        self.scheduler = self._start(
            DASK, "scheduler", "--host", "127.0.0.1", "--port", "0", *NO_DASHBOARD, "--scheduler-file", str(file)
        )
        _wait_for(lambda: file.is_file() and file.stat().st_size > 0, 60, "the scheduler")
        self.address = json.loads(file.read_text())["address"]
        self.workers = [
            self._start(
                DASK,
                "worker",
                self.address,
                "--nthreads",
                "1",
                *NO_DASHBOARD,
                "--no-nanny",
                "--host",
                "127.0.0.1",
                "--name",
                f"w{i}",
            )
            for i in range(workers)
        ]
        with distributed.Client(self.address, timeout=30) as client:
            client.wait_for_workers(workers, timeout=120)

    def _start(self, *command: str) -> subprocess.Popen[bytes]:
        return subprocess.Popen(
            command, cwd=self.folder, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True
        )

    def processes(self) -> list[subprocess.Popen[bytes]]:
        return [self.scheduler, *self.workers]

    def close(self) -> None:
        for proc in self.processes():
            with contextlib.suppress(ProcessLookupError):
                proc.kill()
            proc.wait()


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    """A cluster of two workers for the module's tests: the batch compared with a local one
    runs on it whole, and the test of a killed worker (the last: a cluster it leaves with one
    worker still runs any batch) kills one. A scheduler and a worker are Pythons that import
    distributed (the worker rockyade and the kernels too): started once, not once a test."""
    c = Cluster(tmp_path_factory.mktemp("dask") / "cluster", workers=2)
    try:
        yield c
    finally:
        c.close()


def _study(folder: Path, duration_s: float, runs: int) -> None:
    """A study of ``runs`` reference-DEM runs of specimen 3 rocking freely for ``duration_s``."""
    folder.mkdir(exist_ok=True)
    (folder / "scene.toml").write_text(
        (EXAMPLES / "specimen3_free.toml")
        .read_text()
        .replace("duration_s = 4.0", f"duration_s = {duration_s}")
        .replace("sample_dt_s = 0.001", "sample_dt_s = 0.01")
    )
    thetas = ", ".join(f"{0.02 + 0.005 * i:.3f}" for i in range(runs))
    (folder / "study.toml").write_text(
        f'name = "deploy"\nsolvers = ["reference"]\n[base]\nfile = "scene.toml"\n'
        f'[grid]\n"motion.theta0_rad" = [{thetas}]\n'
    )


def _cpu_s(pid: int) -> float:
    """The CPU seconds ``pid`` used, from /proc (0 once it is gone)."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return 0.0
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def listening_of_trees(pids: list[int]) -> dict[str, tuple[str, int]]:
    """The listening TCP sockets of the processes ``pids`` and every process below them: the
    kernel's tables read once for all (~10 ms a read, per poll), not once a process."""
    mine = socket_inodes({pid for top in pids for pid in (top, *descendants(top))})
    return {inode: where for inode, where in listening_tcp().items() if inode in mine}


def _batch_beside(watch, out: str, *extra: str) -> int:
    """``rockyade batch study.toml --out OUT --quiet ...`` (the command's ``main``, in this
    process, run from the study's folder) with ``watch(running)`` in a thread beside it, to its
    end (``running()`` is False once the batch returned): the exit code. What the tests
    watch, kill and poll are the cluster's processes; a process of its own for the batch only
    added its start-up (Python, rockyade and distributed imported again)."""
    finished = threading.Event()
    failures: list[BaseException] = []

    def watching() -> None:
        try:
            watch(lambda: not finished.is_set())
        except BaseException as exc:  # handed to the test's thread
            failures.append(exc)

    watcher = threading.Thread(target=watching, name="watch-cluster")
    watcher.start()
    try:
        code = main(["batch", "study.toml", "--out", out, "--quiet", *extra])
    finally:
        finished.set()
        watcher.join()
    if failures:
        raise failures[0]
    return code


@pytest.mark.slow
def test_a_batch_on_dask_s_own_scheduler_and_workers_equals_a_local_one_and_listens_on_loopback_only(
    tmp_path, cluster, monkeypatch, capsys
):
    _study(tmp_path, duration_s=8.0, runs=6)
    monkeypatch.chdir(tmp_path)  # both batches run in this process (_batch_beside), from the study's folder
    assert main(["batch", "study.toml", "--out", "local", "--quiet", "--workers", "2"]) == 0, capsys.readouterr().err
    seen: dict = {}

    def poll(running) -> None:
        while running():
            seen.update(listening_of_trees([proc.pid for proc in cluster.processes()]))
            time.sleep(0.05)

    code = _batch_beside(poll, "remote", "--executor", "dask", "--scheduler", cluster.address)  # relative --out
    assert code == 0, capsys.readouterr().err
    assert cluster.address.startswith("tcp://127.0.0.1:")
    assert seen and {host for host, _port in seen.values()} == {"127.0.0.1"}, seen  # no 0.0.0.0, no dashboard
    summary = pd.read_csv(tmp_path / "remote" / "summary.csv")
    pd.testing.assert_frame_equal(comparable(pd.read_csv(tmp_path / "local" / "summary.csv")), comparable(summary))
    assert not (cluster.folder / "remote").exists()  # the run files are the client's, not in the workers' folder


@pytest.mark.slow
def test_a_worker_killed_mid_study_costs_no_run_and_duplicates_none(tmp_path, cluster, monkeypatch, capsys):
    # runs of about half a second of CPU each (100 s simulated); 4: when two have ended, a worker
    # in one of the other two (its CPU seen growing in /proc, polled every 0.05 s) is killed
    # in the middle of it, and the other worker reruns it
    runs = 4
    _study(tmp_path, duration_s=100.0, runs=runs)
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "out"
    killed: list[subprocess.Popen[bytes]] = []

    def kill_a_running_worker(running) -> None:
        _wait_for(lambda: len(list((out / "runs").glob("*.json"))) >= 2 or not running(), 300, "two finished runs")
        before = {proc: _cpu_s(proc.pid) for proc in cluster.workers}
        while running() and not killed:
            time.sleep(0.05)
            for proc in cluster.workers:
                now = _cpu_s(proc.pid)
                if now - before[proc] >= 0.02:  # two clock ticks in 50 ms: running a run
                    killed.append(proc)
                    break
                before[proc] = now
        assert killed, "the batch ended before a worker was killed"
        killed[0].send_signal(signal.SIGKILL)  # in the middle of its run
        killed[0].wait()

    code = _batch_beside(kill_a_running_worker, "out", "--executor", "dask", "--scheduler", cluster.address)
    assert code == 0, capsys.readouterr().err
    [victim] = killed
    assert victim.returncode == -signal.SIGKILL
    assert all(alive(proc.pid) for proc in cluster.workers if proc is not victim)
    summary = pd.read_csv(out / "summary.csv")
    assert list(summary["index"]) == list(range(runs)) and summary.run.is_unique
    assert (summary.status == "completed").all(), summary.failure_reason.tolist()
    assert len(list((out / "runs").glob("*.json"))) == runs and len(list((out / "runs").glob("*.csv"))) == runs
    for run in summary.run:
        data = json.loads((out / "runs" / f"{run}.json").read_text())
        assert data["summary"]["run"] == run and Result.read(out / "runs" / f"{run}.csv").ok
    leftovers = [p for p in out.rglob(".*") if p.name.endswith((".tmp", ".pending", ".lock"))]
    assert not leftovers, leftovers
