"""The generators' parameters described once (issue 32 item 3) and checked everywhere (issue 34
section 5, "Tracebacks"): ``rockyade build`` makes its options from the table and refuses every
number out of its range, naming the option and the range, for every generator; the generators
refuse the same values given from Python, naming their parameter. Never a traceback."""

from __future__ import annotations

import argparse
import inspect
import math

import pytest

from rockyade.cli import main
from rockyade.errors import InputError
from rockyade.scene.generator_options import COMMON, KINDS, OVERBURDEN, Param, options, param
from rockyade.scene.generators import GENERATORS, free_motion, pulse_motion, record_motion, udec_contact


@pytest.fixture(autouse=True, scope="module")
def _one_parser():
    """``main`` builds its argument parser once for this module's ~970 calls, not per call
    (20 ms each, most of this file's time): parsing does not change a parser, so each call
    parses as a fresh ``rockyade`` would."""
    import rockyade.cli

    built = rockyade.cli.build_parser
    parser = built()
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(rockyade.cli, "build_parser", lambda: parser)
        yield
    assert rockyade.cli.build_parser is built


#: Values every numeric option is tried with: zero, negative, not a number, infinite, huge.
FLOATS = ("0", "-2400", "-0.2", "nan", "inf", "-inf", "1e300")
INTEGERS = ("0", "-1", "1000000000", "nan", "inf", "2.5")


def _numeric(kind: str) -> list[Param]:
    return [p for p in options(kind) if p.numeric]


CASES = [(kind, p.name) for kind in KINDS for p in _numeric(kind)]


def _in_range(p: Param, text: str) -> bool | None:
    """Whether the value of ``text`` lies in the option's range (None: not a number it takes)."""
    assert p.range is not None
    try:
        value = int(text) if p.integer else float(text)
    except ValueError:
        return None
    return math.isfinite(value) and p.range.holds(value)


@pytest.mark.parametrize(("kind", "name"), CASES)
def test_every_option_of_every_generator_refuses_a_bad_number_naming_it(kind, name, tmp_path, capsys):
    p = param(kind, name)
    for text in INTEGERS if p.integer else FLOATS:
        out = tmp_path / f"{name}_{text}.toml"
        try:  # OPTION=VALUE: after a space, argparse takes "-inf" for an option
            code = main(["build", kind, f"{p.option}={text}", "--out", str(out)])
        except SystemExit as exc:  # argparse: a count that is not an integer
            code = exc.code
        err = capsys.readouterr().err
        assert "Traceback" not in err and "math domain" not in err and "division" not in err, (kind, name, text, err)
        if _in_range(p, text):
            # a value in range may still be refused with another (an eccentricity without a load)
            assert code in (0, 2), (kind, name, text, err)
            assert code == 0 or len(err.strip().splitlines()) == 1, err
        else:
            assert code == 2, (kind, name, text, err)
            assert p.option in err and p.range is not None, (kind, text, err)
            assert "must be" in err and p.range.text() in err, (kind, text, err)
            assert not out.exists()


@pytest.mark.parametrize(
    ("argv", "option", "words"),
    [
        (["wall", "--unit-height-m=-0.2"], "--unit-height-m", "must be in (0, 1000] m, got -0.2"),
        (["wall", "--density-kg-m3=-2400"], "--density-kg-m3", "must be in [1, 100000] kg/m^3, got -2400"),
        (["arch", "--density-kg-m3=-2400"], "--density-kg-m3", "must be in [1, 100000] kg/m^3, got -2400"),
        (["wall", "--density-kg-m3", "0"], "--density-kg-m3", "must be in [1, 100000] kg/m^3, got 0"),
        (["wall", "--unit-height-m", "0"], "--unit-height-m", "must be in (0, 1000] m, got 0"),
    ],
)
def test_the_five_tracebacks_of_the_review_are_refusals(argv, option, words, tmp_path, monkeypatch, capsys):
    """Issue 34: these gave ValueError (math domain error) and ZeroDivisionError from the joints'
    damping (udec_contact), computed before the generator checked its arguments. The command's
    ``main`` in this process, from the work folder (a traceback would end the test; the
    refusal is ``main``'s return and its error output): a process of its own only added some
    0.7 s of CPU in imports a refusal."""
    monkeypatch.chdir(tmp_path)
    capsys.readouterr()
    code = main(["build", *argv, "--out", "x.toml"])
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.strip() == f"rockyade: error: {option}: {words}"
    assert not (tmp_path / "x.toml").exists()


#: What a parameter applies to (a centre offset: a pointed arch's).
WITH = {"centre_offset_m": {"shape": "pointed"}}


def _generator_params(kind: str) -> list[Param]:
    """The table's numeric parameters that the Python generator of ``kind`` takes."""
    keywords = inspect.signature(GENERATORS[kind]).parameters
    return [p for p in _numeric(kind) if p.name in keywords]


@pytest.mark.parametrize("kind", list(KINDS))
def test_every_generator_refuses_bad_numbers_from_python_naming_the_parameter(kind):
    names = {"restrained-wall": {"wall_height_m", "wall_thickness_m", "wall_length_m"}}
    for p in _generator_params(kind):
        assert p.range is not None
        for value in (0, -1, -0.2, math.nan, math.inf, 1e300, True, "1"):
            try:
                GENERATORS[kind](**{p.name: [value] if p.many else value}, **WITH.get(p.name, {}))
            except InputError as exc:
                assert exc.field.startswith(p.name) or exc.field in names.get(kind, ()), (kind, p.name, value, exc)
            else:
                assert not isinstance(value, (bool, str)) and p.range.holds(value), (kind, p.name, value)


def test_the_helpers_of_the_scene_tables_refuse_bad_numbers_naming_them():
    cases = [
        (lambda v: udec_contact(v, 2400.0), "unit_height_m"),
        (lambda v: udec_contact(0.2, v), "density_kg_m3"),
        (lambda v: udec_contact(0.2, 2400.0, jkn_Pa_per_m=v), "jkn_Pa_per_m"),
        (lambda v: udec_contact(0.2, 2400.0, damping_ratio=v if v != 0 else -1), "damping_ratio"),
        (lambda v: pulse_motion(amplitude_g=v), "amplitude_g"),
        (lambda v: pulse_motion(period_s=v), "period_s"),
        (lambda v: free_motion("b", v if v != 0 else 2.0), "theta0_rad"),
        (lambda v: record_motion("r.at2", v if v != 0 else -1), "load_factor"),
    ]
    for make, field in cases:
        for value in (0, -2400.0, math.nan, math.inf, 1e300):
            with pytest.raises(InputError) as info:
                make(value)
            assert info.value.field == field and "must be" in info.value.message, (field, value)
    assert udec_contact(0.2, 2400.0)["beta_s"] > 0


def test_the_options_of_build_are_the_table_and_the_python_defaults_are_its_defaults():
    from rockyade.cli import build_parser

    parser = build_parser()
    for kind in KINDS:
        sub = _subparser(parser, kind)
        flags = {a.dest: a for a in sub._actions if a.option_strings}
        for p in options(kind):
            action = flags[p.dest]
            assert p.option in action.option_strings and action.default == p.default, (kind, p.option)
            assert action.help == p.help
        keywords = inspect.signature(GENERATORS[kind]).parameters
        for p in _generator_params(kind):
            if not p.many:
                assert keywords[p.name].default == p.default, (kind, p.name)
    assert {p.name for p in COMMON} >= {"density_kg_m3", "jkn_pa_per_m", "friction_angle_deg"}
    assert OVERBURDEN["wall-section"].by_generator and not OVERBURDEN["column"].by_generator


def _subparser(parser, kind):
    build = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices["build"]
    return next(a for a in build._actions if isinstance(a, argparse._SubParsersAction)).choices[kind]


@pytest.mark.parametrize("kind", list(KINDS))
def test_build_help_says_each_default_once(kind, capsys):
    from rockyade.cli import build_parser

    with pytest.raises(SystemExit):
        main(["build", kind, "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "(default: carried) (default: carried)" not in text
    sub = _subparser(build_parser(), kind)
    formatter = sub._get_formatter()
    for action in sub._actions:
        if not action.option_strings or action.help is None:
            continue
        said = formatter._get_help_string(action)
        assert said.count("(default: ") <= 1, (kind, action.dest, said)
        if action.default not in (None, False, argparse.SUPPRESS):
            assert "(default: " in said, (kind, action.dest, said)
