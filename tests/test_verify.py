"""``rockyade verify``: the report runs as a user would run it and its checks pass."""

from __future__ import annotations

import os
import subprocess
import sys

import pandas as pd
import pytest

from rockyade.studies.verify import verify


def _rockyade(*args, cwd):
    return subprocess.run([sys.executable, "-m", "rockyade", *args], capture_output=True, text=True, cwd=cwd)


@pytest.mark.yade
def test_verify_frame_and_pad_from_another_folder(tmp_path):
    """Both DEMs: the frame against Makris & Vassiliou's p_hat, the pad case's overlaps;
    relative output path, exit 0, a CSV of passed rows, a figure per check, index.md."""
    proc = _rockyade("verify", "--only", "frame,pad", "--out", "report", cwd=tmp_path)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    table = pd.read_csv(tmp_path / "report" / "verify.csv")
    assert set(table["check"]) == {"frame", "pad"} and set(table["solver"]) == {"reference", "yade"}
    assert table["passed"].all()
    for name in ("index.md", "verify_frame.png", "verify_pad.png"):
        assert (tmp_path / "report" / name).stat().st_size > 0
    assert "0 failed" in proc.stdout


def test_baseline_unchanged_in_the_reference_dem(tmp_path):
    """The paper's single blocks and bi-block give the peaks and restitution of rockyade 0.1.0."""
    table = verify(tmp_path, ["baseline"], ["reference"])
    assert len(table) >= 30
    assert table["passed"].all(), table[~table["passed"]].to_string()


def test_bad_check_name_is_refused(tmp_path):
    proc = _rockyade("verify", "--only", "frames", "--out", "x", cwd=tmp_path)
    assert proc.returncode == 2 and "only" in proc.stderr and "frame" in proc.stderr
    assert not os.path.exists(tmp_path / "x")


def test_cli_knows_every_check():
    from rockyade.cli.verify import CHECKS as CLI_CHECKS
    from rockyade.studies.verify import CHECK_FUNCTIONS, CHECKS

    assert CLI_CHECKS == CHECKS == tuple(CHECK_FUNCTIONS)
