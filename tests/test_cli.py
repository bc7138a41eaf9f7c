"""The command line: every command, --help, JSON keys, exit codes."""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys

import numpy as np
import pytest

from rockyade.cli import main
from rockyade.result import Result


def run_cli(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.mark.parametrize("command", ["params", "calibrate", "run", "tables"])
def test_help_for_every_command(command):
    proc = subprocess.run([sys.executable, "-m", "rockyade.cli", command, "--help"], capture_output=True, text=True)
    assert proc.returncode == 0 and "usage: rockyade" in proc.stdout


def test_params_json_keys(capsys):
    code, out, _ = run_cli(
        capsys,
        "params",
        "--width",
        "0.25",
        "--height",
        "1.0",
        "--thickness",
        "0.754",
        "--mass",
        "503",
        "--json",
    )
    assert code == 0
    data = json.loads(out)
    for key in ("alpha_rad", "p_rad_s", "mu", "R_m", "I_O_kgm2", "mass_kg", "uplift_accel_m_s2"):
        assert key in data
    assert data["alpha_rad"] == pytest.approx(math.atan(0.25))
    assert data["uplift_accel_m_s2"] == pytest.approx(9.81 * 0.25)


def test_params_from_scene_and_specimen(capsys, examples_dir):
    code, out, _ = run_cli(capsys, "params", "--scene", str(examples_dir / "specimen1_free.toml"), "--json")
    assert code == 0 and json.loads(out)["alpha_rad"] == 0.235
    code, out, _ = run_cli(capsys, "params", "--specimen", "4")  # chamfered: the paper's forms do not apply
    assert code == 0 and "Eq 3 generalised to polygons" in out and "for rectangles" not in out
    code, out, _ = run_cli(capsys, "params", "--specimen", "1")
    assert code == 0 and "(Eq 2)" in out and "Eq 3 for rectangles" in out


def test_calibrate_specimen1_experimental(capsys):
    code, out, _ = run_cli(
        capsys, "calibrate", "--specimen", "1", "--parameters", "experimental", "--method", "paper", "--json"
    )
    assert code == 0
    data = json.loads(out)
    for key in (
        "K_N_per_m",
        "Ks_N_per_m",
        "beta_s",
        "xi_min",
        "f_min_hz",
        "b_eq_m",
        "dt_s",
        "friction_angle_deg",
        "cohesion_Pa",
        "stiffness_scale",
    ):
        assert key in data
    M, R, p = 503, math.hypot(0.125, 0.5), 3.84
    K_eq10 = M / 2 * (p * p + 3 * 9.81 / (4 * R))
    assert data["K_N_per_m"] == pytest.approx(K_eq10 * 1e6)
    gamma = K_eq10 * R
    assert data["beta_s"] == pytest.approx((0.0057 * math.log(gamma / 0.936**2) - 0.0336) ** 2)
    assert data["xi_min"] == pytest.approx(2 * math.pi * data["beta_s"] * 3.84)
    assert data["b_eq_m"] == pytest.approx(0.5 * math.tan(0.235))
    assert data["stiffness_scale"] == "MN/m"


def test_calibrate_text_says_f_min_is_p_in_hz(capsys):
    """Eq 14 sets f_min to the number of p (1/s) in Hz: the line says so, not a bare 3.84 Hz."""
    code, out, _ = run_cli(capsys, "calibrate", "--specimen", "1")
    line = next(x for x in out.splitlines() if "f_min" in x)
    assert code == 0 and "f_min = 3.84 Hz" in line and "p in 1/s" in line


@pytest.mark.parametrize("specimen", ["2", "3", "4", "upper", "lower"])
def test_calibrate_other_specimens(capsys, specimen):
    code, out, _ = run_cli(capsys, "calibrate", "--specimen", specimen, "--json")
    assert code == 0 and json.loads(out)["K_N_per_m"] > 1e8


def test_bad_input_exit_code_and_message(capsys):
    code, _, err = run_cli(capsys, "calibrate", "--specimen", "7")
    assert code == 2 and "specimen" in err and "1, 2, 3, 4, upper, lower" in err
    code, _, err = run_cli(capsys, "calibrate", "--specimen", "1", "--stiffness-scale", "N/m")
    assert code == 2 and "contact.stiffness_scale" in err and "sinks" in err
    code, _, err = run_cli(capsys, "params", "--width", "-1", "--height", "1", "--thickness", "1", "--mass", "1")
    assert code == 2 and "width" in err
    # millimetres for metres: a height a scene refuses is refused here too, naming its range
    code, _, err = run_cli(capsys, "params", "--width", "250", "--height", "2400", "--thickness", "1", "--mass", "1")
    assert code == 2 and "--height: must be in [0.001, 1000] m, got 2400" in err


@pytest.mark.parametrize(
    ("extra", "expected"),
    [
        ([], "--mass: give exactly one of --mass and --density"),
        (["--mass", "3", "--density", "2000"], "--mass: give exactly one of --mass and --density"),
        (["--density", "-1"], "--density: must be a finite number > 0"),
        (["--mass", "3", "--chamfer", "0.2"], "--chamfer: must be in (0, 0.125) m"),
        # a scene's ranges (rockyade.scene.bounds): a density in kg/dm^3 or g/cm^3, a mass in tonnes x 1e9
        (["--density", "2.2e6"], "--density: must be in [1, 100000] kg/m^3, got 2.2e+06"),
        (["--mass", "2e9"], "--mass: must be in [0.001, 1e+09] kg, got 2e+09"),
    ],
)
def test_params_block_errors_name_the_options(capsys, extra, expected):
    """Block.polygon's fields (mass_kg, density_kg_m3, ...) are spoken as the command's options."""
    code, _, err = run_cli(capsys, "params", "--width", "0.25", "--height", "1", "--thickness", "0.754", *extra)
    assert code == 2 and expected in err
    assert "_kg" not in err and "Traceback" not in err


def test_run_housner_writes_csv_whose_peaks_give_mu(capsys, examples_dir, tmp_path):
    out_csv = tmp_path / "r.csv"
    code, out, _ = run_cli(
        capsys, "run", str(examples_dir / "specimen1_free.toml"), "--solver", "housner", "--out", str(out_csv)
    )
    assert code == 0 and "effective mu = 0.936" in out
    result = Result.read(out_csv)
    from rockyade.blocks.restitution import effective_restitution, find_peaks

    mu = effective_restitution(find_peaks(result.t, result.series("theta_rad")), 0.235)
    assert mu == pytest.approx(0.936, abs=2e-5)


def test_tables_command_writes_csvs(capsys, tmp_path):
    code, out, _ = run_cli(capsys, "tables", "--out", str(tmp_path))
    assert code == 0 and "Table 6" in out
    assert (tmp_path / "tables_reproduced.csv").is_file()
    assert (tmp_path / "table5_reproduced.csv").is_file()


def test_run_reference_solver_writes_contacts_and_energy(capsys, examples_dir, tmp_path):
    out_csv = tmp_path / "ref.csv"
    code, out, _ = run_cli(
        capsys, "run", str(examples_dir / "biblock_free.toml"), "--solver", "reference", "--out", str(out_csv)
    )
    assert code == 0 and "upper" in out and "lower" in out
    result = Result.read(out_csv)
    assert result.meta.solver == "reference" and result.blocks == ["lower", "upper"]
    for col in ("upper_theta_rad", "lower_theta_rad", "upper_c0_state", "energy_balance_error_J"):
        assert col in result.frame.columns
    assert result.meta.extra["contact"]["upper"]["stiffness_reading"] == "MN/m"


def test_calibrate_matched_json(capsys):
    code, out, _ = run_cli(capsys, "calibrate", "--specimen", "1", "--method", "matched", "--json")
    assert code == 0
    data = json.loads(out)
    assert data["mu_eff_matched"] == pytest.approx(0.936, rel=0.002)
    assert data["beta_eq13_s"] == pytest.approx(1.98e-4, rel=3e-3)
    assert data["mu_reachable_min"] < 0.936 < data["mu_reachable_max"]
    code, _, err = run_cli(capsys, "calibrate", "--specimen", "lower", "--method", "matched")
    assert code == 1 and "cannot" in err.lower()


@pytest.mark.slow
def test_motion_commands(capsys, tmp_path, monkeypatch):
    monkeypatch.setenv("ROCKYADE_CACHE", str(tmp_path / "cache"))
    rec = tmp_path / "quake.AT2"
    t = np.arange(0, 10, 0.01)
    values = 0.1 * np.sin(2 * np.pi * 2 * t) * np.exp(-0.3 * t)
    rec.write_text(
        "PEER\ntest quake\nACCELERATION IN UNITS OF G\nNPTS= 1000, DT= .0100 SEC\n"
        + "\n".join(" ".join(f"{v:.7E}" for v in values[i : i + 5]) for i in range(0, 1000, 5))
        + "\n"
    )
    code, out, _ = run_cli(capsys, "motion", "info", str(rec), "--json", "--plot", str(tmp_path / "acc.png"))
    info = json.loads(out)
    assert code == 0 and info["npts"] == 1000 and info["dt_s"] == pytest.approx(0.01)
    assert info["units_in_file"] == "g"
    assert info["pga_m_s2"] == pytest.approx(np.max(np.abs(values)) * 9.80665, rel=1e-6)  # standard gravity
    for key in ("duration_s", "pga_time_s"):
        assert key in info
    assert (tmp_path / "acc.png").stat().st_size > 1000
    code, _, _ = run_cli(capsys, "motion", "spectrum", str(rec), "--damping", "0.05", "--out", str(tmp_path / "s.csv"))
    spectrum = __import__("pandas").read_csv(tmp_path / "s.csv")
    assert code == 0 and list(spectrum.columns) == ["period_s", "psa_g", "psa_m_s2"] and len(spectrum) == 100
    out_dir = tmp_path / "suite"
    code, out, _ = run_cli(
        capsys,
        "motion",
        "synth",
        "--type",
        "2",
        "--ground",
        "D",
        "--ag-s",
        "2.8",
        "--count",
        "3",
        "--seed",
        "5",
        "--out",
        str(out_dir),
        "--plot",
        str(tmp_path / "suite.png"),
    )
    assert code == 0 and "compatible" in out
    assert sorted(p.name for p in out_dir.iterdir()) == [
        "record_01.csv",
        "record_02.csv",
        "record_03.csv",
        "suite.json",
    ]
    frame = __import__("pandas").read_csv(out_dir / "record_02.csv")
    assert list(frame.columns) == ["t_s", "accel_m_s2", "vel_m_s", "disp_m"]
    assert abs(frame["vel_m_s"].iloc[-1]) < 1e-3 and abs(frame["disp_m"].iloc[-1]) < 1e-3
    suite = json.loads((out_dir / "suite.json").read_text())
    assert suite["target"]["TC_s"] == 0.3 and suite["settings"]["seed"] == 5
    code, out, _ = run_cli(capsys, "motion", "check", str(out_dir), "--json")
    assert code == 0 and json.loads(out)["ratio_min"] > 0.85
    code, _, err = run_cli(capsys, "motion", "info", str(tmp_path / "missing.AT2"))
    assert code == 2 and "missing.AT2" in err and "not found" in err


@pytest.mark.parametrize("sub", ["info", "spectrum", "synth", "check"])
def test_motion_help(sub, capsys):
    """The parser's help, in this process (``python -m rockyade.cli`` is
    :func:`test_help_for_every_command`'s)."""
    with pytest.raises(SystemExit) as ended:
        main(["motion", sub, "--help"])
    assert ended.value.code == 0 and "usage:" in capsys.readouterr().out


OUTPUT_UNDER_A_FILE = [
    ["build", "column", "--out", "afile/c.toml"],
    ["build", "column", "--out", "c.toml", "--draw", "afile/c.png"],
    ["identify", "{measured}", "--out", "afile/i.json"],
    ["identify", "{measured}", "--plot", "afile/figs"],
    ["identify", "{measured}", "--plot", "afile"],
    ["yade-script", "{scene}", "--out", "afile/y"],
    ["uncertainty", "{study}", "--out", "afile/u"],
    ["run", "{scene}", "--out", "afile/r.csv"],
    ["motion", "synth", "--type", "1", "--ground", "A", "--ag", "2", "--seed", "1", "--out", "afile"],
    ["batch", "{sweep}", "--out", "afile"],
]


@pytest.mark.parametrize("argv", OUTPUT_UNDER_A_FILE, ids=[" ".join(a[:1] + a[-2:]) for a in OUTPUT_UNDER_A_FILE])
def test_an_output_under_a_file_is_refused_before_any_work(argv, capsys, tmp_path, monkeypatch):
    """Every --out/--plot/--draw whose folder is a file: one line naming the option, exit 2,
    and nothing written (as ``run`` does)."""
    from tests.conftest import EXAMPLES

    paths = {
        "measured": EXAMPLES / "measured" / "specimen1_free_rocking.csv",
        "scene": EXAMPLES / "specimen1_free.toml",
        "study": EXAMPLES / "studies" / "uncertainty_specimen1.toml",
        "sweep": EXAMPLES / "studies" / "harmonic_sweep.toml",
    }
    monkeypatch.chdir(tmp_path)
    (tmp_path / "afile").write_text("a file, not a folder\n")
    code, _, err = run_cli(capsys, *[a.format(**paths) for a in argv])
    option = next(a for a in argv if a.startswith("--") and "afile" in argv[argv.index(a) + 1])
    assert code == 2 and err.startswith(f"rockyade: error: {option}: ") and err.count("\n") == 1, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile"]


@pytest.mark.parametrize(
    ("command", "study", "typo", "key"),
    [
        ("batch", "harmonic_sweep.toml", "solver", "solvers"),
        ("uncertainty", "uncertainty_specimen1.toml", "solver", "solvers"),
        ("uncertainty", "uncertainty_specimen1.toml", "theta_over_alpha_level", "theta_over_alpha_levels"),
    ],
)
def test_study_file_misspelt_key_gets_did_you_mean(command, study, typo, key, capsys, tmp_path):
    """A study file reads its keys like a scene file: a misspelt optional key is named with the
    key it resembles, not only the list of allowed keys."""
    from tests.conftest import EXAMPLES

    text = (EXAMPLES / "studies" / study).read_text()
    studies = tmp_path / "examples" / "studies"
    studies.mkdir(parents=True)
    (tmp_path / "examples" / "specimen1_harmonic.toml").symlink_to(EXAMPLES / "specimen1_harmonic.toml")
    (tmp_path / "examples" / "specimen3_free.toml").symlink_to(EXAMPLES / "specimen3_free.toml")
    (studies / study).write_text(text.replace(f"\n{key} =", f"\n{typo} =", 1))
    code, _, err = run_cli(capsys, command, str(studies / study), "--out", str(tmp_path / "out"))
    assert code == 2 and f"{typo}: unknown key; did you mean {key}?" in err and err.count("\n") == 1, err


def test_motion_info_plot_says_what_it_wrote(capsys, tmp_path, monkeypatch):
    """Like every command that writes a file: 'wrote PATH' (on stderr after --json, so that
    stdout stays one JSON document)."""
    from tests.conftest import EXAMPLES

    record = str(EXAMPLES / "records" / "ricker_pulse_T0.5s.AT2")
    monkeypatch.chdir(tmp_path)
    code, out, _ = run_cli(capsys, "motion", "info", record, "--plot", "x.png")
    assert code == 0 and out.splitlines()[-1] == "wrote x.png" and (tmp_path / "x.png").stat().st_size > 0
    code, out, err = run_cli(capsys, "motion", "info", record, "--plot", "y.png", "--json")
    assert code == 0 and json.loads(out)["npts"] == 1001 and err.strip() == "wrote y.png"


def test_a_mistyped_option_or_command_shows_that_commands_usage_and_the_nearest_name(capsys):
    """Issue "What users hit" 14: ``--ouput`` printed the top-level usage with no suggestion."""
    cases = [
        (
            ["motion", "spectrum", "rec.AT2", "--ouput", "s.csv"],
            "usage: rockyade motion spectrum",
            "did you mean --out?",
        ),
        (["run", "scene.toml", "--solvr", "housner"], "usage: rockyade run", "did you mean --solver?"),
        (["rn", "scene.toml"], "usage: rockyade ", "did you mean 'run'?"),
        (["motion", "spectrm", "rec.AT2"], "usage: rockyade motion ", "did you mean 'spectrum'?"),
        (["motion", "info", "rec.AT2", "--accel-units", "gg"], "usage: rockyade motion info", "did you mean 'g'?"),
    ]
    for argv, usage, hint in cases:
        with pytest.raises(SystemExit) as stopped:
            main(argv)
        err = capsys.readouterr().err
        assert stopped.value.code == 2, argv
        assert err.startswith(usage) and hint in err, (argv, err)
    with pytest.raises(SystemExit) as stopped:  # nothing near: no guess
        main(["motion", "info", "rec.AT2", "--zzzzzz"])
    err = capsys.readouterr().err
    assert stopped.value.code == 2 and "unrecognized arguments: --zzzzzz" in err and "did you mean" not in err


def _subparsers():
    """Every sub-command's parser (nested ones too), by its prog."""
    import argparse

    from rockyade.cli import build_parser

    found, todo = {}, [build_parser()]
    while todo:
        parser = todo.pop()
        found[parser.prog] = parser
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                todo.extend(action.choices.values())
    return found


def test_no_help_prints_a_doubled_percent_sign():
    """argparse %-formats help strings but not descriptions: a description written "95 %%"
    printed as such (crosscheck's did)."""
    doubled = [prog for prog, parser in _subparsers().items() if "%%" in parser.format_help()]
    assert not doubled


def test_the_solver_options_help_lists_the_registrys_solvers():
    """crosscheck --help and compare --help name every registered solver (the how-to page
    sends readers to crosscheck --help for them)."""
    from rockyade.solvers import solver_names

    parsers = _subparsers()
    for prog in ("rockyade crosscheck", "rockyade compare"):
        text = " ".join(parsers[prog].format_help().split())
        assert "among " + ", ".join(solver_names()) in text, prog


def test_one_dt_factor_range_everywhere(capsys):
    """The time-step factor's range is [DT_FACTOR_MIN, 1] in every check, help and doc: --dt-factors
    1,1e-6 used to pass crosscheck's own check ((0, 1]) and be refused by the solver with another
    message; Siconos took any factor in (0, 1]."""
    from rockyade.errors import InputError
    from rockyade.solvers import make_solver
    from rockyade.solvers.base import DT_FACTOR_MIN
    from rockyade.studies.crosscheck import check_dt_factors

    from .conftest import ROOT

    interval = f"[{DT_FACTOR_MIN:g}, 1]"
    with pytest.raises(InputError, match=re.escape(interval)) as err:
        check_dt_factors((1.0, 1e-6))
    assert err.value.field == "--dt-factors"
    for name in ("housner", "reference", "yade", "siconos"):
        with pytest.raises(InputError, match=re.escape(interval)):
            make_solver(name, dt_factor=1e-6)
    parsers = _subparsers()
    assert interval in " ".join(parsers["rockyade compare"].format_help().split())
    assert interval in " ".join(parsers["rockyade crosscheck"].format_help().split())
    for page in (ROOT / "docs/siconos.md", ROOT / "docs/verification.md"):
        assert not re.search(r"dt_factor`? \(in \(0, 1\]", page.read_text()), page
