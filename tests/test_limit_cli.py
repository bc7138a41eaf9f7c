"""``rockyade limit``: text, JSON keys, exit codes, the plot, bad input."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import pytest

from rockyade.cli import main
from rockyade.scene.generators import rest_motion, stack, write_scene

from .conftest import EXAMPLES

JSON_KEYS = (
    "load_multiplier",
    "direction",
    "mechanism",
    "hinges",
    "sliding",
    "friction_angle_deg",
    "status",
    "alpha0",
    "e_star",
    "M_star_kg",
    "a0_star_m_s2",
    "d0_star_m",
    "du_star_m",
    "Ts_s",
)


def run_cli(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.fixture
def squat(tmp_path):
    """A block 2.0 m wide and 0.4 m tall, friction 10 degrees."""
    path = tmp_path / "squat.toml"
    contact = {"calibration": "paper", "friction_angle_deg": 10.0}
    write_scene(path, stack(widths_m=[2.0], heights_m=0.4, contact=contact, motion=rest_motion()))
    return path


def test_limit_json_has_the_documented_keys(capsys):
    code, out, _ = run_cli(capsys, "limit", str(EXAMPLES / "assemblies/frame.toml"), "--json")
    assert code == 0
    data = json.loads(out)
    for key in JSON_KEYS:
        assert key in data, key
    assert data["status"] == "collapse" and data["direction"] == "+x"
    assert data["load_multiplier"] == pytest.approx(0.125 / 0.75)  # a column's b / h
    assert set(data["mechanism"]) == {"column_left", "column_right", "beam"}
    assert set(data["mechanism"]["beam"]) == {"vx", "vy", "omega"}
    assert len(data["hinges"]) == 4 and data["sliding"] == []
    assert data["friction_angle_deg"] == 30.0 and data["alpha0"] == data["load_multiplier"]
    assert data["checks"]["virtual_work_residual"] < 1e-9


@pytest.mark.slow
def test_direction_minus_x_is_read_as_a_value(capsys):
    scene = str(EXAMPLES / "assemblies/column_8_drums.toml")
    _, out_plus, _ = run_cli(capsys, "limit", scene, "--json")
    code, out_minus, _ = run_cli(capsys, "limit", scene, "--direction", "-x", "--json")
    assert code == 0
    plus, minus = json.loads(out_plus), json.loads(out_minus)
    assert minus["direction"] == "-x" and minus["load_multiplier"] == pytest.approx(plus["load_multiplier"])
    assert plus["hinges"][0]["point_m"][0] == pytest.approx(0.15) and minus["hinges"][0]["point_m"][0] == -0.15
    code, out, _ = run_cli(capsys, "limit", scene, "--direction=-x", "--json")
    assert code == 0 and json.loads(out)["direction"] == "-x"


def test_friction_and_no_sliding_choose_the_mechanism(capsys, squat):
    code, out, _ = run_cli(capsys, "limit", str(squat))
    assert code == 0
    assert "load multiplier lambda = 0.1763" in out and "b01 slides towards +x on the base" in out
    assert "associated" in out and "nonlinear: none" in out
    code, out, _ = run_cli(capsys, "limit", str(squat), "--no-sliding")
    assert code == 0 and "lambda = 5.0000" in out and "b01 turns clockwise on the base about (1, 0) m" in out
    assert "associated" not in out and "d0* = 1 m" in out
    code, out, _ = run_cli(capsys, "limit", str(squat), "--friction-angle-deg", "20", "--json")
    assert json.loads(out)["load_multiplier"] == pytest.approx(math.tan(math.radians(20)))


def test_an_assembly_that_cannot_stand_exits_1(capsys, tmp_path):
    data = stack(widths_m=[0.4, 0.4], heights_m=0.4, motion=rest_motion())
    data["blocks"][1]["position_m"][0] = 0.3  # the upper block's centroid beyond the lower's edge
    path = tmp_path / "overhang.toml"
    write_scene(path, data)
    code, out, _ = run_cli(capsys, "limit", str(path))
    assert code == 1 and "cannot stand under gravity" in out and "lambda =" not in out
    code, out, _ = run_cli(capsys, "limit", str(path), "--json")
    data = json.loads(out)
    assert code == 1 and data["status"] == "unstable" and data["load_multiplier"] is None


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--friction-angle-deg", "95"], "--friction-angle-deg: must be in [0, 89.9] degrees"),
        (["--friction-angle-deg", "nan"], "--friction-angle-deg: must be"),
        (["--fc", "0.5"], "--fc: must be in [1, 10]"),
        (["--plot", "mechanism.txt"], "--plot: must be a .png file"),
    ],
)
def test_bad_input_exits_2_with_one_line(capsys, squat, extra, message):
    code, out, err = run_cli(capsys, "limit", str(squat), *extra)
    assert code == 2 and out == ""
    assert message in err and len(err.strip().splitlines()) == 1


def test_a_missing_scene_and_clashing_options_exit_2(tmp_path, capsys):
    """The command's ``main`` in this process (a traceback would be an exception raised here;
    argparse's refusal is its SystemExit, the process's exit code)."""
    for argv in (
        [str(tmp_path / "nope.toml")],
        [str(EXAMPLES / "assemblies/frame.toml"), "--no-sliding", "--friction-angle-deg", "30"],
        [str(EXAMPLES / "assemblies/frame.toml"), "--direction", "+y"],
    ):
        try:
            code = main(["limit", *argv])
        except SystemExit as exit_:
            code = exit_.code
        err = capsys.readouterr().err
        assert code == 2 and "Traceback" not in err and "error" in err, err


@pytest.mark.slow
def test_the_plot_is_written_and_json_stays_clean(capsys, tmp_path):
    png = tmp_path / "figs" / "arch.png"
    code, out, err = run_cli(
        capsys, "limit", str(EXAMPLES / "assemblies/arch_pointed_fixed_piers.toml"), "--json", "--plot", str(png)
    )
    assert code == 0 and json.loads(out)["status"] == "collapse"
    assert f"wrote {png}" in err
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000


def test_the_plot_of_an_unstable_assembly_says_so(capsys, tmp_path):
    data = stack(widths_m=[0.4, 0.4], heights_m=0.4, motion=rest_motion())
    data["blocks"][1]["position_m"][0] = 0.3
    write_scene(tmp_path / "overhang.toml", data)
    code, out, _ = run_cli(capsys, "limit", str(tmp_path / "overhang.toml"), "--plot", str(tmp_path / "o.png"))
    assert code == 1 and (tmp_path / "o.png").is_file() and "unstable" in out


def test_limit_is_listed_in_the_help():
    proc = subprocess.run([sys.executable, "-m", "rockyade.cli", "--help"], capture_output=True, text=True)
    assert proc.returncode == 0 and "limit" in proc.stdout
    proc = subprocess.run([sys.executable, "-m", "rockyade.cli", "limit", "--help"], capture_output=True, text=True)
    assert proc.returncode == 0 and "--no-sliding" in proc.stdout and "Circolare" in proc.stdout
