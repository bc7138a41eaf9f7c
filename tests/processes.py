"""Shared test helpers: YADE present or the test skipped (failed where it is required), and
processes read from /proc (children, liveness)."""

from __future__ import annotations

import os
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
