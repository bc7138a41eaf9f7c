"""Shared test helpers: YADE present or the test skipped (failed where it is required), and
processes read from /proc (children, liveness)."""

from __future__ import annotations

import os
import signal
from pathlib import Path

import pytest


def require_yade() -> None:
    """Skip without YADE; fail instead where ``ROCKYADE_REQUIRE_YADE=1`` (``make test``, CI)."""
    # imported here, not with the module: YADE's backend brings the calibration and the
    # reference DEM's kernels (~1.5 s of CPU), which test_ctrl_c_workers' fresh Pythons, that
    # import this module for fake_program alone, paid for nothing
    from rockyade.yade import backend as yade_backend

    if yade_backend.yade_available():
        return
    message = f"YADE is not installed ({yade_backend.YADE_PYTHON}, {yade_backend.YADE_PY_DIR}): apt-get install yade"
    if os.environ.get("ROCKYADE_REQUIRE_YADE") == "1":
        pytest.fail(message)
    pytest.skip(message)


def require_siconos() -> None:
    """Skip without Siconos; fail instead where ``ROCKYADE_REQUIRE_SICONOS=1`` (``make test``, CI)."""
    from rockyade.siconos import backend as siconos_backend

    if siconos_backend.siconos_available():
        return
    message = f"Siconos is not installed ({siconos_backend.SICONOS_MODULE}): apt-get install python3-siconos"
    if os.environ.get("ROCKYADE_REQUIRE_SICONOS") == "1":
        pytest.fail(message)
    pytest.skip(message)


def descendants(pid: int) -> set[int]:
    """Every process below ``pid``."""
    found: set[int] = set()
    todo = [pid]
    while todo:
        parent = todo.pop()
        try:
            tasks = os.listdir(f"/proc/{parent}/task")
        except OSError:
            continue
        for tid in tasks:
            try:
                children = Path(f"/proc/{parent}/task/{tid}/children").read_text().split()
            except OSError:
                continue
            for child in map(int, children):
                if child not in found:
                    found.add(child)
                    todo.append(child)
    return found


def alive(pid: int) -> bool:
    """True while ``pid`` runs (a zombie is not running)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def listening_tcp() -> dict[str, tuple[str, int]]:
    """Every listening TCP socket of this machine (IPv4 and IPv6): inode -> (address, port),
    the address as /proc/net/tcp* gives it, decoded ("0.0.0.0", "127.0.0.1", "::", ...)."""
    import ipaddress

    found = {}
    for name in ("/proc/net/tcp", "/proc/net/tcp6"):
        try:
            lines = Path(name).read_text().splitlines()[1:]
        except FileNotFoundError:
            continue
        for line in lines:
            fields = line.split()
            if fields[3] != "0A":  # LISTEN
                continue
            address, port = fields[1].split(":")
            raw = bytes.fromhex(address)
            # the kernel prints each 32-bit word in host (little-endian) order
            raw = b"".join(raw[i : i + 4][::-1] for i in range(0, len(raw), 4))
            found[fields[9]] = (str(ipaddress.ip_address(raw)), int(port, 16))
    return found


def socket_inodes(pids: set[int]) -> set[str]:
    """Inodes of the sockets the processes ``pids`` hold."""
    import re

    found = set()
    for pid in pids:
        try:
            fds = os.listdir(f"/proc/{pid}/fd")
        except OSError:
            continue
        for fd in fds:
            try:
                m = re.match(r"socket:\[(\d+)\]", os.readlink(f"/proc/{pid}/fd/{fd}"))
            except OSError:
                continue
            if m:
                found.add(m.group(1))
    return found


def listening_of_tree(pid: int) -> dict[str, tuple[str, int]]:
    """The listening TCP sockets of ``pid`` and every process below it."""
    mine = socket_inodes({pid, *descendants(pid)})
    return {inode: where for inode, where in listening_tcp().items() if inode in mine}


def cmdline(pid: int) -> str:
    """The command line of ``pid`` ("" when it is gone)."""
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
    except OSError:
        return ""


def sigint_default() -> None:
    """``preexec_fn`` of a child that a test interrupts with SIGINT: SIGINT's default action in
    it, whatever the test run inherited (a shell starts a background job with SIGINT ignored,
    and a Python started so ignores Ctrl-C)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


#: A worker driver without an engine: the loop (rockyade/io/driver_loop.py, its path the first
#: argument), loaded by path as the real drivers load it; a job's scene is JSON: ``name`` (printed
#: to the job's log), ``raise`` (the scene raises), ``sleep_s`` (the scene's run time).
FAKE_DRIVER = """
import json, runpy, sys, time, types
loop = types.SimpleNamespace(**runpy.run_path(sys.argv[1], run_name="driver_loop"))
class Recorder:
    status, stop_time, stop_body, overturn_times, k, start, flushes = "completed", None, None, {}, 2, 0.0, 0
def run(scene, out, deadline, flush_s):
    with open(scene) as fh:
        job = json.load(fh)
    if job.get("raise"):
        raise RuntimeError("the scene raised")
    print("running", job["name"])
    time.sleep(job.get("sleep_s", 0.0))
    import numpy as np
    meta = loop.output_meta(Recorder(), True, steps=7, version="fake 1.0", dt_s=0.1, max_residual=1e-9)
    loop.write_output(out, np.savez, {"pos": np.zeros((2, 1, 2))}, meta)
    return "completed"
loop.exit_now(loop.serve(int(sys.argv[3]), run))
"""


def fake_program():
    """The engine-free driver (FAKE_DRIVER) as rockyade starts a worker's program, named "Fake"."""
    import sys

    from rockyade.io import driver_loop
    from rockyade.io.warm_program import Program

    return Program([sys.executable, "-c", FAKE_DRIVER, driver_loop.__file__], {}, "Fake", "--fake-timeout", 30.0)
