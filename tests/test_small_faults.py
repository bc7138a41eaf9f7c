"""Smaller faults of issue 26 item 7, each refused or answered in words: options matched by
their whole name only, a count the generator would divide by, options that would be silently
ignored, a scene with no lateral capacity (friction 0), and records whose units look wrong."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from rockyade.cli import build_parser, main
from rockyade.constants import STANDARD_GRAVITY
from rockyade.motion.records import RecordError, read_record, units_warning

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SPECIMEN = EXAMPLES / "specimen1_free.toml"


def _parsers(parser: argparse.ArgumentParser, path: str = "rockyade"):
    yield path, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _parsers(sub, f"{path} {name}")


def test_every_parser_matches_options_by_their_whole_name_only():
    seen = list(_parsers(build_parser()))
    assert len(seen) > 20  # every command and sub-command, not the top parser alone
    abbreviating = [path for path, parser in seen if parser.allow_abbrev]
    assert abbreviating == []


@pytest.mark.parametrize(
    "argv",
    [
        ["motion", "spectrum", "REC", "--spectrum-typ", "1"],
        ["run", "SCENE", "--sol", "housner"],
        ["fragility", "SCENE", "--suite", "paper", "--record", "DIR", "--out", "x"],
    ],
)
def test_an_option_prefix_is_refused(argv, capsys, tmp_path):
    argv = [str(SPECIMEN) if a == "SCENE" else str(tmp_path) if a == "DIR" else a for a in argv]
    argv = [str(EXAMPLES / "records" / "ricker_pulse_T0.5s.AT2") if a == "REC" else a for a in argv]
    with pytest.raises(SystemExit) as info:
        main(argv)
    assert info.value.code == 2
    assert "unrecognized arguments" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("argv", "option"),
    [
        (["build", "wall-section", "--courses", "0"], "--courses"),
        (["build", "wall-section", "--overburden-eccentricity-m", "0.05"], "--overburden-eccentricity-m"),
        (["build", "column", "--top-load-eccentricity-m", "0.01"], "--top-load-eccentricity-m"),
        # without --friction-rule a coulomb pass may run (the code's quantities), so only the associated rule ignores it
        (["limit", str(SPECIMEN), "--friction-rule", "associated", "--max-iterations", "5"], "--max-iterations"),
    ],
)
def test_a_count_or_an_ignored_option_is_refused_naming_it(argv, option, capsys, tmp_path):
    if argv[0] == "build":
        argv = [*argv, "--out", str(tmp_path / "s.toml")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert f"error: {option}:" in err
    assert "Traceback" not in err
    assert not (tmp_path / "s.toml").exists()


def test_max_iterations_is_taken_with_the_coulomb_rule(capsys):
    assert main(["limit", str(SPECIMEN), "--friction-rule", "coulomb", "--max-iterations", "5"]) == 0


def _frictionless(tmp_path: Path) -> Path:
    text = SPECIMEN.read_text().replace('calibration = "paper"', 'calibration = "paper"\nfriction_angle_deg = 0.0')
    path = tmp_path / "f0.toml"
    path.write_text(text)
    return path


def test_a_frictionless_scene_has_lambda_zero_not_minus_zero(tmp_path, capsys):
    assert main(["limit", str(_frictionless(tmp_path))]) == 0
    out = capsys.readouterr().out
    # the printed multipliers (not the scene's path, which may hold pytest-0/): never negative zero
    numbers = re.findall(r"(?:lambda|multiplier)\w*\s*=\s*(\S+)", out)
    assert numbers and not any(n.startswith("-0") for n in numbers), numbers
    assert "lambda = 0.0000" in out
    assert "no lateral capacity" in out


def test_a_frictionless_scene_gets_no_default_levels_and_no_option_blamed(tmp_path, capsys):
    code = main(["fragility", str(_frictionless(tmp_path)), "--suite", "paper", "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 1
    assert "no lateral capacity" in err
    assert "--levels:" not in err
    assert not re.search(r"(?<![\w./-])-0(?:\.0*)?(?![\d.])", err.replace(str(tmp_path), "<tmp>")), err


def _at2(path: Path, unit_line: str, values: list[float]) -> Path:
    lines = [
        "PEER NGA STRONG MOTION DATABASE RECORD",
        "Test, 1/1/2000, station, 000",
        unit_line,
        f"NPTS= {len(values)}, DT= .0100 SEC",
    ]
    lines += [f"{v:15.7E}" for v in values]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize(
    ("unit_line", "values", "pga_g"),
    [
        # 0.5 g written in g under a cm/s2 header: read as 0.5 cm/s2, 0.0005 g
        ("ACCELERATION TIME SERIES IN UNITS OF CM/S/S", [0.0, 0.5, -0.2, 0.1], 0.5 / 100 / STANDARD_GRAVITY),
        # 470 cm/s2 under an m/s2 header: read as 470 m/s2, 48 g
        ("ACCELERATION TIME SERIES IN UNITS OF M/S/S", [0.0, 470.0, -200.0, 100.0], 470.0 / STANDARD_GRAVITY),
    ],
)
def test_an_implausible_pga_warns_and_names_units(tmp_path, capsys, unit_line, values, pga_g):
    path = _at2(tmp_path / "r.AT2", unit_line, values)
    record = read_record(path)
    assert record.pga_m_s2 / STANDARD_GRAVITY == pytest.approx(pga_g, rel=1e-6)
    message = units_warning(record)
    assert message is not None and "--units" in message
    err = capsys.readouterr().err
    assert "warning" in err and "--units" in err and str(path) in err
    read_record(path)  # once per file and process
    assert capsys.readouterr().err == ""


def test_a_plausible_record_does_not_warn(capsys):
    record = read_record(EXAMPLES / "records" / "ricker_pulse_T0.5s.AT2")
    assert units_warning(record) is None
    assert "warning" not in capsys.readouterr().err


def test_a_unitless_at2_is_refused_naming_units(tmp_path):
    path = _at2(tmp_path / "r.AT2", "ACCELERATION TIME SERIES", [0.0, 0.1, -0.1])
    with pytest.raises(RecordError, match="--units"):
        read_record(path)
