"""The documentation stands alone and is true: no path outside the project, the paper
cited by its title, a licence that matches pyproject, links that resolve, the paper's
inconsistency counts in step with ``rockyade tables``, and every command and Python
block of the README and docs/ runs as printed from a fresh checkout (relative paths): the
indented commands each in a fresh folder, the fenced ones page by page in order (a later one
may read what an earlier one wrote), and where a page shows a command's output (``$ command``
then its lines) the lines it shows are the ones printed, in that order (``...`` stands for
lines left out; a wall time is a number that may differ)."""

from __future__ import annotations

import json
import os
import re
import select
import shlex
import signal
import subprocess
import sys
import tomllib
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import pytest

from .conftest import ROOT
from .test_examples import GALLERY, GALLERY_RUN, RECORDS_RUN, check_gallery_figure, check_generated_records

TITLE = "Modeling the dynamic behavior of masonry walls as rigid blocks"
DOCS = sorted((ROOT / "docs").rglob("*.md"))
PAGES = [
    ROOT / "README.md",
    *DOCS,
    ROOT / "examples/records/README.md",
    ROOT / "examples/site_records/README.md",
    ROOT / "examples/gallery/README.md",
]
BIN = Path(sys.executable).parent
#: Paths of the development machine that users do not have (spelled so that this file
#: does not contain them).
OUTSIDE = ("../" + "shared", "/work/" + "shared")
#: Commands of the docs that need more than a test can give, each with the reason: the whole
#: paper study and the assemblies' verification (``make run`` runs both: minutes), a Dask
#: cluster and a study named by placeholders (``SCHEDULER``, ``tcp://host``, ``STUDY.toml``).
NOT_RUN_HERE = ("rockyade paper", "rockyade verify", "SCHEDULER", "tcp://host", "STUDY.toml")
#: What may differ between the page and the run in a shown output line: wall times.
VOLATILE = (re.compile(r"wall time [0-9.e+-]+ s"), re.compile(r", [0-9.e+-]+ s \(total\)"))


#: Checks of what a documented command wrote, made after it ran as printed (folder, printed
#: text): the examples' own (tests/test_examples.py), so each script runs once in the suite.
AFTER: dict[str, Callable[[Path, str], None]] = {
    RECORDS_RUN: check_generated_records,
    **{GALLERY_RUN.format(stem=script.stem): partial(check_gallery_figure, script.stem) for script in GALLERY},
}


def _shown(page: Path) -> list[tuple[str, list[str], bool]]:
    """Every command of the page, in order: (command, the output lines the page shows after it,
    whether it is in a fenced block). Indented blocks: `.venv/bin/...` lines; fenced blocks:
    `rockyade ...` or `.venv/bin/rockyade ...` lines (continued by a trailing backslash, a
    trailing ``# comment`` dropped). Output: the lines after a ``$ command`` up to a blank line,
    the next command or the block's end."""
    out: list[tuple[str, list[str], bool]] = []
    fenced = False
    lines = page.read_text().splitlines()
    i = 0
    while i < len(lines):
        line = lines[i]
        i += 1
        if line.lstrip().startswith("```"):
            fenced = not fenced
            continue
        pattern = r"^\s*(\$ )?((?:\.venv/bin/)?rockyade [a-z].*)$" if fenced else r"^ {4}(\$ )?(\.venv/bin/\S+.*)$"
        m = re.match(pattern, line)
        if not m:
            continue
        command = m.group(2)
        while command.endswith("\\") and i < len(lines):
            command = command[:-1] + " " + lines[i].strip()
            i += 1
        command = " ".join(re.sub(r"\s+#.*$", "", command).split())
        shown: list[str] = []
        while m.group(1) and i < len(lines) and lines[i].strip() and not lines[i].lstrip().startswith("```"):
            if re.match(pattern, lines[i]) or not (fenced or lines[i].startswith("    ")):
                break
            if lines[i].lstrip().startswith("$ "):  # another program's command (yade ...): no more output
                break
            shown.append(lines[i] if fenced else lines[i][4:])
            i += 1
        out.append((command, shown, fenced))
    return out


def _commands(page: Path) -> list[str]:
    """Every `.venv/bin/...` line of the page's indented blocks, in order."""
    return [c for c, _, fenced in _shown(page) if not fenced and not any(skip in c for skip in NOT_RUN_HERE)]


def _bare(command: str) -> str:
    """``command`` as a fenced block prints it: ``rockyade ...``, not ``.venv/bin/rockyade ...``."""
    return re.sub(r"^\.venv/bin/(?=rockyade )", "", command)


#: The output lines each command's page shows (the first page that shows any).
OUTPUTS = {c: shown for page in reversed(PAGES) for c, shown, _ in _shown(page) if shown}
#: Pages with fenced commands, run in order in one folder per page.
FENCED = {
    page.relative_to(ROOT).as_posix(): [
        (c, shown) for c, shown, fenced in _shown(page) if fenced and not any(skip in c for skip in NOT_RUN_HERE)
    ]
    for page in PAGES
}
FENCED = {page: commands for page, commands in FENCED.items() if commands}
#: Each documented indented command once (pages repeat some), with the first page that shows
#: it; one that a page's fenced block prints too is run there (see ALSO_SHOWN), not twice.
COMMANDS = {
    command: page.relative_to(ROOT).as_posix()
    for page in reversed(PAGES)
    for command in _commands(page)
    if not any(_bare(command) == _bare(c) for commands in FENCED.values() for c, _ in commands)
}
#: The output lines the pages' indented blocks show for a command a fenced block runs: checked
#: against that run, beside the fenced page's own.
ALSO_SHOWN = {
    _bare(c): shown
    for page in reversed(PAGES)
    for c, shown, fenced in _shown(page)
    if shown and not fenced and any(_bare(c) == _bare(f) for commands in FENCED.values() for f, _ in commands)
}


def _same(shown: str, printed: str) -> bool:
    """A shown output line is the printed one (wall times aside)."""
    for pattern in VOLATILE:
        shown, printed = pattern.sub("<time>", shown), pattern.sub("<time>", printed)
    return shown.rstrip() == printed.rstrip()


def check_output(command: str, shown: list[str], printed: str) -> None:
    """Every line the page shows is printed, in the page's order (``...``: lines left out)."""
    lines = printed.splitlines()
    at = 0
    for want in shown:
        if want.strip() == "...":
            continue
        found = next((k for k in range(at, len(lines)) if _same(want, lines[k])), None)
        assert found is not None, f"{command}\nthe page shows:\n  {want}\nnot printed (in order) in:\n{printed[-3000:]}"
        at = found + 1


@dataclass
class Ran:
    """A finished command: its exit code and what it printed."""

    returncode: int
    stdout: str
    stderr: str


class CommandStarter:
    """The documented commands, each run in its own process forked from a Python that has
    imported rockyade once (``tests/command_server.py``): as printed, without ~2 s of imports
    per command. The console script itself is run from a shell by the CLI's own tests."""

    def __init__(self, scratch: Path) -> None:
        self.scratch = scratch
        self.count = 0
        self.cpu_s = 0.0  # the commands' CPU seconds, theirs and their children's
        self.proc = subprocess.Popen(
            [sys.executable, str(ROOT / "tests/command_server.py")],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        assert self._reply(600) == {"ready": True}

    def _reply(self, timeout: float) -> dict:
        assert self.proc.stdout is not None
        ready, _, _ = select.select([self.proc.stdout], [], [], timeout)
        line = self.proc.stdout.readline() if ready else ""
        if not line:
            raise AssertionError(f"the command starter gave no answer within {timeout:.0f} s")
        return json.loads(line)

    def run(self, kind: str, cwd: Path, argv: list[str] = (), code: str = "", env: dict | None = None) -> Ran:
        """Run one command (``kind``: rockyade, script or code) in ``cwd``; 600 s at most."""
        assert self.proc.stdin is not None
        self.count += 1
        out, err = self.scratch / f"{self.count}.out", self.scratch / f"{self.count}.err"
        request = {"kind": kind, "argv": list(argv), "code": code, "cwd": str(cwd), "env": env}
        self.proc.stdin.write(json.dumps({**request, "stdout": str(out), "stderr": str(err)}) + "\n")
        self.proc.stdin.flush()
        pid = self._reply(60)["pid"]
        try:
            reply = self._reply(600)
            returncode = reply["returncode"]
            self.cpu_s += reply["cpu_s"]
        except AssertionError:
            os.kill(pid, signal.SIGKILL)
            raise
        return Ran(returncode, out.read_text(errors="replace"), err.read_text(errors="replace"))

    def close(self) -> None:
        assert self.proc.stdin is not None
        self.proc.stdin.close()
        self.proc.wait(60)


@pytest.fixture(scope="session")
def _started(tmp_path_factory) -> Iterator[CommandStarter]:
    started = CommandStarter(tmp_path_factory.mktemp("commands"))
    yield started
    started.close()


@pytest.fixture
def starter(_started: CommandStarter, record_property) -> Iterator[CommandStarter]:
    """The session's command starter; the CPU its commands spent in this test is recorded as the
    test's property ``forked_cpu_s`` (counted by ``$ROCKYADE_TEST_CPU_LOG``, conftest.py)."""
    before = _started.cpu_s
    yield _started
    record_property("forked_cpu_s", _started.cpu_s - before)


def run_printed(starter: CommandStarter, command: str, cwd: Path, env: dict | None = None) -> Ran:
    """``command`` as a shell would run it in ``cwd``: ``.venv/bin/rockyade ...`` or
    ``rockyade ...`` by the console script's entry point, ``.venv/bin/python FILE ...`` as a
    script."""
    args = shlex.split(command)
    program = Path(args[0]).name
    if program == "rockyade":
        return starter.run("rockyade", cwd, args[1:], env=env)
    assert program == "python", f"{command}: a program the docs' tests do not know"
    return starter.run("script", cwd, args[1:], env=env)


def _run_as_printed(starter: CommandStarter, command: str, cwd: Path, shown: list[str], also: list[str] = ()) -> str:
    """Run ``command`` in ``cwd`` with this environment's rockyade; exit 0 (or 2 where the page
    shows the refusal) and the shown lines printed (and ``also``, what another page shows after
    the same command, each page's lines in its own order)."""
    proc = run_printed(starter, command, cwd)
    refused = any(line.startswith("rockyade: error:") for line in [*shown, *also])
    assert proc.returncode == (2 if refused else 0), f"{command}\n{proc.stdout[-1500:]}\n{proc.stderr[-2500:]}"
    check_output(command, shown, proc.stdout + proc.stderr)
    check_output(command, list(also), proc.stdout + proc.stderr)
    return proc.stdout + proc.stderr


def _without_plot(command: str, keep: set[str]) -> str:
    """``command`` without its ``--plot PATH`` unless ``keep`` names that path."""
    match = re.search(r" --plot (\S+)", command)
    if match is None or match.group(1) in keep:
        return command
    return command[: match.start()] + command[match.end() :]


def _python_blocks() -> list[tuple[str, str, list[str]]]:
    """(page, code, setup): each Python block, with the page's earlier commands whose ``--out``
    is a file the block names (it reads what they wrote), without their ``--plot`` where the
    block does not name the figure (the command itself runs as printed in its own test)."""
    out = []
    for page in PAGES:
        text = page.read_text()
        for m in re.finditer(r"```python\n(.*?)```", text, re.S):
            code = m.group(1)
            quoted = set(re.findall(r"[\"']([^\"'\s]+\.\w+)[\"']", code))
            setup = [
                _without_plot(c.group(1).strip(), quoted)
                for c in re.finditer(r"^\s*(?:\$ )?(?:\.venv/bin/)?(rockyade .*)$", text[: m.start()], re.M)
                if quoted & set(re.findall(r"--out (\S+)", c.group(1)))
            ]
            out.append((page.relative_to(ROOT).as_posix(), code, setup))
    return out


def _fresh_checkout(tmp_path: Path) -> Path:
    """A folder that looks like a clone to relative paths: its examples, no outputs."""
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    return tmp_path


# ------------------------------------------------------------------ standing alone


def test_no_file_points_outside_the_project():
    tracked = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True).stdout.split()
    offenders = []
    for name in tracked:
        path = ROOT / name
        if path.suffix in {".png", ".npz"} or not path.is_file():
            continue
        text = path.read_text(errors="replace")
        if any(outside in text for outside in OUTSIDE):
            offenders.append(name)
    assert offenders == []


def test_the_paper_is_cited_by_its_title():
    for page in (ROOT / "README.md", ROOT / "docs/paper.md", ROOT / "docs/index.md"):
        assert TITLE in " ".join(page.read_text().split()), page


def test_licence_matches_pyproject():
    licence = (ROOT / "LICENSE").read_text()
    assert "GNU GENERAL PUBLIC LICENSE" in licence and "Version 2, June 1991" in licence
    assert "any later version" in licence  # the "or later" clause the SPDX id relies on
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert project["license"] == "GPL-2.0-or-later"


def test_readme_keeps_the_two_set_up_commands():
    readme = (ROOT / "README.md").read_text()
    assert "    apt-get update && apt-get install -y make && make run\n" in readme
    assert "    apt-get update && apt-get install -y make && make test\n" in readme


def test_links_resolve():
    broken = []
    for page in PAGES:
        for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", page.read_text()):
            if target.startswith(("http://", "https://")) or target.startswith("reports/"):
                continue
            if not (page.parent / target).exists():
                broken.append(f"{page.relative_to(ROOT)} -> {target}")
    assert broken == []


def test_docs_index_links_every_docs_page():
    index = (ROOT / "docs/index.md").read_text()
    for page in DOCS:
        if page.name != "index.md":
            assert page.relative_to(ROOT / "docs").as_posix() in index, page


def test_inconsistency_counts_in_the_paper_page_match_the_tables_command():
    from rockyade.paper.tables import reproduction_report

    table = reproduction_report()
    text = (ROOT / "docs/paper.md").read_text()
    for number in range(1, 7):
        part = table[table.table == number]
        flagged = f"| {int((~part.consistent).sum())} of {len(part)} |"
        row = next(line for line in text.splitlines() if line.startswith(f"| {number} ("))
        assert flagged in row, (row, flagged)


def test_motion_type_table_lists_every_motion_type():
    import rockyade.motion  # noqa: F401  (registers every type)
    from rockyade.motion.spec import MOTION_TYPES

    text = (ROOT / "docs/howto/run-a-scene.md").read_text()
    listed = set(re.findall(r"^\| `([\w-]+)` \|", text.split("Motion types", 1)[1].split("\n\n", 2)[1], re.M))
    assert listed == set(MOTION_TYPES)


@pytest.mark.parametrize("page", ["README.md", "docs/howto/run-a-scene.md"])
def test_the_example_error_message_is_the_real_one(page, tmp_path):
    """The pages quote the message for mu = 1.2: it is what load_scene says."""
    from rockyade.errors import InputError
    from rockyade.scene import load_scene

    quoted = re.search(r"`(scene\.toml: blocks\[0\]\.mu: [^`]+)`", (ROOT / page).read_text()).group(1)
    text = re.sub(r"(?m)^mu = .*$", "mu = 1.2", (ROOT / "examples/specimen1_free.toml").read_text())
    (tmp_path / "scene.toml").write_text(text)
    with pytest.raises(InputError) as info:
        load_scene(tmp_path / "scene.toml")
    assert str(info.value).replace(str(tmp_path / "scene.toml"), "scene.toml") == quoted


def test_python_page_shows_keyword_only_arguments_as_such():
    """A function the Python page lists with its arguments: a keyword-only one is shown after
    ``*`` or as ``name=...``, never as a bare positional name."""
    import importlib
    import inspect

    text = (ROOT / "docs/python.md").read_text()
    for dotted, shown in re.findall(r"`(rockyade(?:\.\w+)+)\(([^)`]*)\)`", text):
        module, name = dotted.rsplit(".", 1)
        try:
            func = getattr(importlib.import_module(module), name)
        except (ImportError, AttributeError):
            continue  # a method or attribute path, e.g. Block.rectangle
        params = inspect.signature(func).parameters
        shown_args = [a.strip() for a in shown.split(",")]
        star = shown_args.index("*") if "*" in shown_args else len(shown_args)
        for i, arg in enumerate(shown_args[:star]):
            if arg in params and params[arg].kind is inspect.Parameter.KEYWORD_ONLY:
                raise AssertionError(f"python.md: {dotted}({shown}): {arg} (argument {i + 1}) is keyword-only")


# ------------------------------------------------------------------ runs as printed


@pytest.mark.slow
@pytest.mark.parametrize("command", list(COMMANDS), ids=[f"{COMMANDS[c]}: {c[18:80]}" for c in COMMANDS])
def test_documented_command_runs_as_printed(command, tmp_path, starter):
    """Each indented command of the README and docs/, in a fresh folder (no command needs
    another's output), prints the lines its page shows (one that a fenced block prints too is
    run and checked with that block's page, ``ALSO_SHOWN``), and what it wrote passes the
    examples' checks where it has some (``AFTER``)."""
    printed = _run_as_printed(starter, command, _fresh_checkout(tmp_path), OUTPUTS.get(command, []))
    if command in AFTER:
        AFTER[command](tmp_path, printed)


@pytest.mark.slow
@pytest.mark.parametrize("page", list(FENCED))
def test_fenced_commands_run_as_printed(page, tmp_path, starter):
    """The fenced commands of a page, in order in one folder, print the lines the page shows."""
    cwd = _fresh_checkout(tmp_path)
    (cwd / "runs").mkdir()
    for command, shown in FENCED[page]:
        _run_as_printed(starter, command, cwd, shown, ALSO_SHOWN.get(_bare(command), []))


def test_shown_output_is_compared_line_by_line():
    """The comparison finds a changed line, a line out of order and lets ``...`` and a wall
    time through (the docs' outputs are checked by the slow tests above)."""
    printed = "wrote a.csv\nsolver housner: status completed, wall time 0.01 s\n  max = 1\n"
    check_output("c", ["wrote a.csv", "...", "solver housner: status completed, wall time 2.5 s"], printed)
    with pytest.raises(AssertionError, match="max = 2"):
        check_output("c", ["wrote a.csv", "  max = 2"], printed)
    with pytest.raises(AssertionError, match=r"wrote a\.csv"):
        check_output("c", ["  max = 1", "wrote a.csv"], printed)
    assert any(shown for shown in OUTPUTS.values()) and FENCED  # the pages' outputs and fenced commands are found


@pytest.mark.slow
@pytest.mark.parametrize(("page", "code", "setup"), _python_blocks(), ids=[p for p, _, _ in _python_blocks()])
def test_documented_python_runs_as_printed(page, code, setup, tmp_path, starter):
    (_fresh_checkout(tmp_path) / "runs").mkdir()
    for command in setup:  # the page's commands that write what the block reads
        proc = run_printed(starter, command, tmp_path)
        assert proc.returncode == 0, f"{page}: {command}\n{proc.stderr[-2500:]}"
    env = {"MPLBACKEND": "Agg", "PATH": str(BIN), "HOME": str(Path.home())}
    proc = starter.run("code", tmp_path, code=code, env=env)
    assert proc.returncode == 0, f"{page}\n{code}\n{proc.stderr[-2500:]}"


def test_readme_lists_every_registered_solver():
    """The README's "Solvers" section names each solver of the registry, and no page counts
    fewer solvers than there are or waits for one that is registered."""
    from rockyade.solvers import solver_names

    readme = (ROOT / "README.md").read_text()
    section = readme.split("\n## Solvers\n", 1)[1].split("\n## ", 1)[0]
    assert re.findall(r"^\* `(\w+)`:", section, re.M) == list(solver_names())
    assert "the three solvers" not in readme.lower()
    assert "once it is registered" not in (ROOT / "docs/verification.md").read_text()
