"""A benchmark script's quick mode run in the test's process, as ``make bench-all`` runs it
(``benchmarks/run_all.py``: ``runpy``, the script's own ``sys.argv``, its folder leading
``sys.path``): a process of its own paid Python's start and rockyade's imports again."""

from __future__ import annotations

import runpy
import sys
from pathlib import Path

import pytest


def run_quick(script: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], *args: str) -> str:
    """``python SCRIPT --quick ARGS`` in this process: what it printed on stdout (it must end with
    exit status 0; its error output is in the failure's message)."""
    monkeypatch.setattr(sys, "argv", [str(script), "--quick", *args])
    monkeypatch.setattr(sys, "path", [str(script.parent), *sys.path])
    capsys.readouterr()
    try:
        runpy.run_path(str(script), run_name="__main__")
    except SystemExit as exc:
        assert exc.code in (None, 0), f"{script.name} exited {exc.code}\n{capsys.readouterr().err[-3000:]}"
    return capsys.readouterr().out
