"""Shared test helpers: YADE present or the test skipped (failed where it is required), and
processes read from /proc (children, liveness)."""

from __future__ import annotations

import os
import signal
from pathlib import Path

import pytest

from rockyade.yade import backend as yade_backend


def require_yade() -> None:
    """Skip without YADE; fail instead where ``ROCKYADE_REQUIRE_YADE=1`` (``make test``, CI)."""
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
