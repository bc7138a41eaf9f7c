"""``rockyade verify``: the report runs as a user would run it and its checks pass."""

from __future__ import annotations

import os
import subprocess
import sys

import pandas as pd
import pytest

from rockyade.cli import main
from rockyade.studies.verification import verify


def _rockyade(*args, cwd):
    return subprocess.run([sys.executable, "-m", "rockyade", *args], capture_output=True, text=True, cwd=cwd)


@pytest.mark.yade
def test_verify_frame_and_pad_from_another_folder(tmp_path, monkeypatch, capsys):
    """Both DEMs: the frame against Makris & Vassiliou's p_hat, the pad case's overlaps;
    relative output path, exit 0, a CSV of passed rows, a figure per check, index.md. (The
    command's ``main`` in this process, run from another folder: a process of its own would only
    add its start-up.)"""
    monkeypatch.chdir(tmp_path)
    code = main(["verify", "--only", "frame,pad", "--out", "report"])
    proc = capsys.readouterr()
    assert code == 0, proc.out + proc.err
    table = pd.read_csv(tmp_path / "report" / "verify.csv")
    assert set(table["check"]) == {"frame", "pad"} and set(table["solver"]) == {"reference", "yade"}
    assert table["passed"].all()
    for name in ("index.md", "verify_frame.png", "verify_pad.png"):
        assert (tmp_path / "report" / name).stat().st_size > 0
    assert "0 failed" in proc.out


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
    from rockyade.studies.verification import CHECK_FUNCTIONS, CHECKS

    assert CLI_CHECKS == CHECKS == tuple(CHECK_FUNCTIONS)


@pytest.mark.slow
def test_loaded_block_checks_run_from_the_command_and_pass(tmp_path, monkeypatch, capsys):
    """``--only loaded_block,loaded_pushover``: the limit analysis and Housner's uplift give
    (W b + N d) / (W h_c) within 1e-6, the reference DEM's pushover onset lies within 2 % of it
    (the command's ``main``, in this process)."""
    monkeypatch.chdir(tmp_path)
    code = main(["verify", "--only", "loaded_block,loaded_pushover", "--no-yade", "--out", "report"])
    assert code == 0, capsys.readouterr()
    table = pd.read_csv(tmp_path / "report" / "verify.csv")
    assert list(table["check"]) == ["loaded_block"] * 2 + ["loaded_pushover"] * 2
    assert set(table["solver"]) == {"limit", "housner", "reference"}
    assert table["passed"].all(), table.to_string()
    expected = (1000 * 9.81 * 0.2 + 8000 * 0.15) / (1000 * 9.81 * 1.0)
    assert table["expected"].to_numpy() == pytest.approx(expected, rel=1e-6)
    block = table[table["check"] == "loaded_block"]
    assert (block["difference"].abs() <= 1e-6 * expected).all()
    onset = float(table.loc[2, "value"])
    assert expected <= onset <= 1.02 * expected
    assert (tmp_path / "report" / "verify_loaded_pushover.png").stat().st_size > 0


def test_loaded_mass_check_gives_the_closed_form_with_the_loads_mass(tmp_path):
    """``--only loaded_mass``: the block 0.4 x 2 m (1000 kg) with N = 8 kN at d = 0.15 m and its
    mass N / g at h_N = 2 m: lambda = (9810 x 0.2 + 8000 x 0.15) / (9810 x 1 + 8000 x 2)
    = 3162 / 25810 = 0.122511 from the limit analysis and Housner; e* = (9810 + 16000)^2 /
    ((9810 + 8000)(9810 + 32000)) = 0.894606."""
    table = verify(tmp_path / "report", ["loaded_mass"], ["reference"])
    assert list(table["check"]) == ["loaded_mass"] * 3 and table["passed"].all(), table.to_string()
    assert table["value"].to_numpy()[:2] == pytest.approx(3162.0 / 25810.0, rel=1e-6)
    assert table["value"].to_numpy()[2] == pytest.approx(25810.0**2 / (17810.0 * 41810.0), rel=1e-6)


@pytest.mark.slow
def test_the_checks_an_engineer_signs_pass(tmp_path):
    """``--only loaded_classical,code_friction,crushing`` (issue 33): the loaded wall's alpha 0.0841 rad
    towards +x and 0.1239 towards -x, each mu and uplift multiplier by hand; the frictionless corner's
    1.3019 under both rules, the 35 degree corner's coulomb 1.6205 below the associated 3.5891 and
    taken; a block's (B - a) / H with crushing, and the rigid multiplier as fm tends to infinity."""
    table = verify(tmp_path / "report", ["loaded_classical", "code_friction", "crushing"], ["reference"])
    assert table["passed"].all(), table.to_string()
    assert list(table["check"]).count("loaded_classical") == 8 and list(table["check"]).count("crushing") == 3
    alphas = table[table["quantity"].str.startswith("alpha towards")]["value"].to_numpy()
    assert alphas.round(4).tolist() == [0.0841, 0.1239]
    friction = table[table["check"] == "code_friction"].set_index("quantity")["value"]
    assert friction["35 deg corner: the code's lambda = the lower"] == pytest.approx(1.6205, abs=5e-5)


@pytest.mark.slow
def test_limit_pushover_check_passes_against_the_closed_forms(tmp_path):
    """``limit_pushover``: the limit analysis gives b/h = 0.2 for the block, 17/35 for the restrained
    wall's three hinges, tan(30 deg) for the sliding panel and 0.1494 for the arch, and the
    reference DEM's onset is within 2 % of each (at or above it, the levels being 1 % apart)."""
    import math

    table = verify(tmp_path, ["limit_pushover"], ["reference"])
    assert list(table["solver"]) == ["reference"] * 4
    assert table["passed"].all(), table.to_string()
    expected = dict(zip([q.split(":")[0] for q in table["quantity"]], table["expected"], strict=True))
    assert expected["block"] == pytest.approx(0.2, rel=1e-9)
    assert expected["restrained wall"] == pytest.approx(17 / 35, rel=1e-9)
    assert expected["panel"] == pytest.approx(math.tan(math.radians(30.0)), rel=1e-6)
    assert expected["arch"] == pytest.approx(0.1494, abs=1e-4)
    ratio = table["value"] / table["expected"]
    assert ((ratio >= 1.0 - 1e-5) & (ratio <= 1.02)).all(), table.to_string()
