"""Fuzzing the command line: random commands with odd option values end with an exit code
(0 success, 1 failed run, 2 bad input, 3 unavailable solver) and at most one line of error,
never a traceback or a hang."""

from __future__ import annotations

import atexit
import contextlib
import io
import os
import shutil
import tempfile
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rockyade.cli import main

from .conftest import EXAMPLES
from .fuzzing import COUNTS, fuzz_settings, outcome, report

FOLDER = Path(tempfile.mkdtemp(prefix="rockyade-fuzz-cli-"))
atexit.register(shutil.rmtree, FOLDER, True)  # the suite leaves nothing in the temporary folder
RECORD = FOLDER / "quake.AT2"
RECORD.write_text(
    "PEER\nquake\nACCELERATION IN UNITS OF G\nNPTS= 10, DT= .0100 SEC\n"
    "  .1000000E-01  .2000000E-01 -.1000000E-01  .0000000E+00  .5000000E-02\n"
    "  .1000000E-01 -.2000000E-01  .1000000E-01  .0000000E+00 -.5000000E-02\n"
)
SCENES = [str(p) for p in sorted(EXAMPLES.glob("specimen*_free.toml"))]
BLOCKER = FOLDER / "a_file"
BLOCKER.write_text("x")

VALUES = st.one_of(
    st.sampled_from(
        [
            "0",
            "-1",
            "1",
            "2",
            "95",
            "1e400",
            "nan",
            "inf",
            "-inf",
            "abc",
            "",
            "1_0",
            "\u0661",
            "0.001",
            "1e-300",
            "30",
            "N/m",
            "MN/m",
            "upper",
            "7",
            "g",
            "cm/s2",
            "furlong",
            str(RECORD),
            str(BLOCKER / "x"),
            str(FOLDER / "missing.toml"),
            *SCENES,
            "--json",
            "--",
            "-",
            "tcp://127.0.0.1:9",
        ]
    ),
    st.text(max_size=8),
)
#: Values of the options that write: never a file of the project (a scene must not become a PNG).
OUTPUTS = st.sampled_from(
    [
        "",
        "-",
        "x.png",
        "x.csv",
        "sub/x.csv",
        "sub/x.png",
        "x.toml",
        str(BLOCKER),
        str(BLOCKER / "x.csv"),
        str(FOLDER / "cmp"),
        "/proc/x.csv",
    ]
)
WRITERS = ("--out", "--plot")

COMMANDS = {
    "params": [
        "--specimen",
        "--width",
        "--height",
        "--thickness",
        "--mass",
        "--density",
        "--inertia",
        "--vertices",
        "--chamfer",
        "--scene",
        "--block",
    ],
    "calibrate": ["--specimen", "--parameters", "--stiffness-scale", "--friction-angle"],
    "run": ["--solver", "--out", "--plot"],
    "motion info": ["--units", "--format", "--dt"],
    "motion spectrum": ["--units", "--damping", "--t-min", "--t-max", "-n", "--out"],
    "compare": ["--solvers", "--reference", "--out"],
}
FLAGS = {"params": ["--json"], "calibrate": ["--json"], "motion info": ["--json"], "run": ["--allow-large"]}
POSITIONAL = {"run": SCENES, "motion info": [str(RECORD)], "motion spectrum": [str(RECORD)], "compare": SCENES}


@st.composite
def command_lines(draw: st.DrawFn) -> list[str]:
    command = draw(st.sampled_from(sorted(COMMANDS)))
    argv = command.split()
    if command in POSITIONAL and draw(st.integers(0, 9)):
        argv.append(draw(st.sampled_from(POSITIONAL[command])))
    for option in draw(st.lists(st.sampled_from(COMMANDS[command]), max_size=4)):
        argv += [option, draw(OUTPUTS if option in WRITERS else VALUES)]
    for flag in draw(st.lists(st.sampled_from(FLAGS.get(command, ["--json"])), max_size=1)):
        argv.append(flag)
    if command == "compare":  # the default solvers include YADE: keep the fuzz quick
        argv += ["--solvers", draw(st.sampled_from(["housner", "housner,reference", "nope", ""]))]
    if command in ("run", "compare") and "--out" not in argv:
        argv += ["--out", str(FOLDER / ("out.csv" if command == "run" else "cmp"))]
    return argv


def _main(argv: list[str]) -> int:
    before = {p: p.stat().st_mtime_ns for p in EXAMPLES.glob("*")}
    out, err = io.StringIO(), io.StringIO()
    cwd = os.getcwd()
    os.chdir(FOLDER)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main(argv)
            except SystemExit as exc:  # argparse: usage error (2) or --help (0)
                code = exc.code if isinstance(exc.code, int) else 2
    finally:
        os.chdir(cwd)
    assert {p: p.stat().st_mtime_ns for p in EXAMPLES.glob("*")} == before, argv  # the project's files untouched
    text = err.getvalue()
    assert "Traceback" not in text, text
    if code == 2 and text.startswith("rockyade: error:"):
        assert text.count("\n") == 1, text  # one line
    assert code in (0, 1, 2, 3), (argv, code, text)
    if code != 0:
        raise _RefusedError(code)
    return code


class _RefusedError(Exception):
    """A clean non-zero exit."""

    def __init__(self, code: int) -> None:
        super().__init__(code)
        COUNTS["cli exit codes"][f"exit {code}"] += 1


@pytest.mark.slow
@fuzz_settings(60)
@given(command_lines())
def test_fuzz_command_lines(argv):
    outcome("cli", lambda: _main(argv), clean=(_RefusedError,))


@pytest.fixture(scope="module", autouse=True)
def _print_counts():
    yield
    print("\n" + report("cli") + "; " + ", ".join(f"{k}: {v}" for k, v in sorted(COUNTS["cli exit codes"].items())))
