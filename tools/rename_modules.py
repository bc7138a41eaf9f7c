"""Rename modules whose basenames said nothing on their own, and every reference to them.

Run from a repository root (``python tools/rename_modules.py``; ``--dry-run`` lists what it
would do). For each row of :data:`RENAMES` it moves the file with ``git mv`` (a row already
done, the old file gone and the new one there, is skipped), then rewrites every reference in
the text files git knows (tracked, and untracked but not ignored): ``*.py``, ``*.md``,
``*.toml``, ``*.cfg``, ``*.ini``, ``*.txt``, ``*.rst``, ``*.yml``, ``*.sh`` and the Makefile,
so ``pyproject.toml``'s import-linter contracts, ``docs/``, ``tests/`` and ``benchmarks/`` too:

* dotted module paths, in code, strings (``mock.patch``, ``monkeypatch``,
  ``importlib.import_module``) and docs: ``rockyade.dem.frames`` and
  ``rockyade.dem.frames.dem_frame`` become ``rockyade.dem.result_frames[...]``, never
  ``rockyade.dem.frames_x``;
* ``from rockyade.dem import frames`` (one name or a list, parenthesised or not):
  ``frames as f`` becomes ``result_frames as f``, a bare ``frames`` becomes
  ``result_frames as frames`` (the file's code keeps working; the line is printed so that a
  reader can drop the alias);
* file paths in docs and comments: ``rockyade/dem/frames.py``, ``dem/frames.py``,
  ``dem/frames`` (two or more trailing parts of the path, with or without ``.py``);
* the module's bare name in its package's ``__init__.py`` (the word frames in double backquotes in
  ``rockyade/dem/__init__.py``, where the package lists its modules), and the module's
  name after its package's (``solvers.cost``) in the files that are not Python (docs,
  ``pyproject.toml``: in Python ``limit.model`` may be an attribute);
* a renamed page of ``docs/`` wherever its file name stands (links, ``docs/x.md``);
* a renamed test module's name wherever it stands (``tests/test_x.py``, ``from .test_x``,
  ``-k``);
* the few sentences that name a module by its bare basename (:data:`LITERAL_EDITS`), where
  that sentence is still found.

Then ruff sorts the imports of the Python files changed and formats them (``python -m ruff``
of the Python that runs this script). Every rewrite matches whole names only, and the new
names never contain an old one as a whole name, so a second run changes nothing. Files
added later are rewritten like the others.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from pathlib import Path

#: (old path, new path), relative to the repository root.
RENAMES: list[tuple[str, str]] = [
    # model.py: five models of different things; dem/model.py keeps the name (the DEM model)
    ("rockyade/calibration/model.py", "rockyade/calibration/model_stage.py"),
    ("rockyade/identification/model.py", "rockyade/identification/forward_model.py"),
    ("rockyade/limit/model.py", "rockyade/limit/rigid_blocks.py"),
    ("rockyade/scene/model.py", "rockyade/scene/description.py"),
    # the command keeps cli/crosscheck.py; the others say what they hold
    ("rockyade/analysis/crosscheck.py", "rockyade/analysis/crosscheck_statistics.py"),
    ("rockyade/figures/crosscheck.py", "rockyade/figures/paired_ratios.py"),
    ("rockyade/studies/crosscheck.py", "rockyade/studies/crosscheck_study.py"),
    # the command keeps cli/verify.py
    ("rockyade/studies/verify.py", "rockyade/studies/verification.py"),
    ("rockyade/figures/verify.py", "rockyade/figures/verification_histories.py"),
    ("rockyade/studies/checks.py", "rockyade/studies/verification_checks.py"),
    ("rockyade/figures/checks.py", "rockyade/figures/legibility.py"),
    # the command keeps cli/uncertainty.py
    ("rockyade/studies/uncertainty.py", "rockyade/studies/uncertainty_study.py"),
    ("rockyade/figures/uncertainty.py", "rockyade/figures/uncertainty_bands.py"),
    # studies/report.py keeps the name (the report every study writes)
    ("rockyade/assess/report.py", "rockyade/assess/report_lines.py"),
    ("rockyade/limit/report.py", "rockyade/limit/report_text.py"),
    # the command keeps cli/fragility.py
    ("rockyade/assess/fragility.py", "rockyade/assess/fragility_analysis.py"),
    ("rockyade/probability/fragility.py", "rockyade/probability/fragility_curves.py"),
    ("rockyade/assess/fit.py", "rockyade/assess/stripe_fit.py"),
    # cost.py: three different costs
    ("rockyade/limit/cost.py", "rockyade/limit/analysis_cost.py"),
    ("rockyade/runner/cost.py", "rockyade/runner/cost_limits.py"),
    ("rockyade/solvers/cost.py", "rockyade/solvers/cost_estimate.py"),
    # contacts.py: three different contacts
    ("rockyade/kernel/contacts.py", "rockyade/kernel/narrowphase.py"),
    ("rockyade/limit/contacts.py", "rockyade/limit/point_contacts.py"),
    ("rockyade/yade/contacts.py", "rockyade/yade/contact_plan.py"),
    # common.py: cli/common.py keeps the name (what the command modules share)
    ("rockyade/figures/common.py", "rockyade/figures/canvas.py"),
    ("rockyade/scene/generators/common.py", "rockyade/scene/generators/scene_tables.py"),
    # worker.py: the generic warm program, and YADE's
    ("rockyade/io/worker.py", "rockyade/io/warm_program.py"),
    ("rockyade/yade/worker.py", "rockyade/yade/warm_worker.py"),
    # paper/specimens.py keeps the name (the paper's specimens)
    ("rockyade/studies/specimens.py", "rockyade/studies/specimen_scenes.py"),
    # scene/placement.py keeps the name (where a scene's blocks stand)
    ("rockyade/kernel/placement.py", "rockyade/kernel/world.py"),
    # the commands keep cli/motion.py, cli/limit.py, cli/identify.py, cli/assess.py, cli/build.py
    ("rockyade/figures/motion.py", "rockyade/figures/base_motions.py"),
    ("rockyade/figures/limit.py", "rockyade/figures/collapse_mechanism.py"),
    ("rockyade/figures/identify.py", "rockyade/figures/identification_fit.py"),
    ("rockyade/figures/assess.py", "rockyade/figures/wall_assessment.py"),
    ("rockyade/figures/fragility.py", "rockyade/figures/fragility_panels.py"),
    ("rockyade/figures/overturning.py", "rockyade/figures/overturning_spectrum.py"),
    ("rockyade/dem/build.py", "rockyade/dem/model_from_scene.py"),
    # generators are named after the structures they build (arches, columns, frames, walls)
    ("rockyade/dem/frames.py", "rockyade/dem/result_frames.py"),
    ("rockyade/motion/columns.py", "rockyade/motion/text_columns.py"),
    # a module named for what it does
    ("rockyade/io/lifetime.py", "rockyade/io/parent_death.py"),
    # "reliability" is a probability of failure to a structural engineer; these test robustness,
    # and the page says what a run guarantees
    ("tests/test_reliability_batch.py", "tests/test_robust_batch.py"),
    ("tests/test_reliability_cache.py", "tests/test_robust_cache.py"),
    ("tests/test_reliability_cli.py", "tests/test_robust_cli.py"),
    ("tests/test_reliability_inputs.py", "tests/test_robust_inputs.py"),
    ("tests/test_reliability_links.py", "tests/test_robust_links.py"),
    ("tests/test_reliability_records.py", "tests/test_robust_records.py"),
    ("docs/reliability.md", "docs/robustness.md"),
]

#: Sentences that name a module by its bare basename, per file: (old text, new text). Each is
#: applied where the old text is still found (another change may have reworded it: then the
#: line is reported, not guessed at).
LITERAL_EDITS: dict[str, list[tuple[str, str]]] = {
    "docs/architecture.md": [
        (
            "| `cli/` | the `rockyade` command, one module per command group;",
            "| `cli/` | the `rockyade` command, one module per command or group of commands, named after it "
            "(`verify.py` is `rockyade verify`, `blocks.py` `params` and `calibrate`);",
        ),
        (
            "  under the name the CLI uses.\n",
            "  under the name the CLI uses.\n"
            "* **A new module**: named after what it holds (`studies/verification.py`, "
            "`figures/verification_histories.py`),\n"
            "  a command's module after the command (`cli/verify.py`); no two modules share a basename\n"
            "  (`tests/test_module_names.py`) but for the same role in sibling packages, which say so in\n"
            "  their docstrings: `payload`, `driver` and `backend` of `yade/` and `siconos/`.\n",
        ),
        (
            "verification (`verify.py`,",
            "verification (`verification.py`,",
        ),
        (
            "the JSON payload (`payload`, `contacts`)",
            "the JSON payload (`payload`, `contact_plan`)",
        ),
        (
            "the DEM model both DEMs run (`build`, `model`, `joints`)",
            "the DEM model both DEMs run (`model_from_scene`, `model`, `joints`)",
        ),
        (
            "result frames and the kernel's driver",
            "result frames (`result_frames`) and the kernel's driver",
        ),
        (
            "one `calibrate(block, contact)` and the model stage `calibrated_model(scene)`",
            "one `calibrate(block, contact)` and the model stage `calibrated_model(scene)` (`model_stage`)",
        ),
        (
            "the scene: one validated description of a simulation for every solver (`loading`, `model`)",
            "the scene: one validated description of a simulation for every solver (`loading`, `description`)",
        ),
        (
            "state records, placement, broad phase,",
            "state records, placement (`world`), broad phase, narrow phase (`narrowphase`),",
        ),
        (
            "stopping on Ctrl-C, worker lifetime, cost checks and progress",
            "stopping on Ctrl-C, worker lifetime, cost checks (`cost_limits`) and progress",
        ),
        (
            "atomic writes, locks (never through a link), typed and range-checked reading of tables",
            "atomic writes, locks (never through a link), typed and range-checked reading of tables, "
            "a program kept warm (`warm_program`), children that die with their parent (`parent_death`)",
        ),
    ],
    "docs/robustness.md": [
        ("# Reliability: bounded inputs", "# Robustness: bounded inputs"),
        ("(`tests/test_reliability_*.py`,", "(`tests/test_robust_*.py`,"),
    ],
    "docs/index.md": [("* [Reliability](robustness.md)", "* [Robustness](robustness.md)")],
    "docs/howto/base-motions.md": [("([reliability](../robustness.md", "([robustness](../robustness.md")],
    "README.md": [("identification and uncertainty, reliability\n", "identification and uncertainty, robustness\n")],
    "rockyade/limit/__init__.py": [
        (
            "the mechanism is drawn by :mod:`rockyade.figures.collapse_mechanism`.\nSee docs/limit.md.",
            "the mechanism is drawn by\n:mod:`rockyade.figures.collapse_mechanism`. See docs/limit.md.",
        ),
    ],
    "rockyade/scene/loading.py": [
        ("(see scene.model.JointOverride)", "(see scene.description.JointOverride)"),
        ("(see scene.model.LoadSpec)", "(see scene.description.LoadSpec)"),
    ],
    "rockyade/scene/__init__.py": [
        (
            "``model`` (the validated dataclasses and cross-field checks)",
            "``description`` (the validated dataclasses and cross-field checks)",
        ),
    ],
    "rockyade/calibration/__init__.py": [
        (
            "running the model builder and the engine on the block alone) and ``model``",
            "running the model builder and the engine on the block alone) and ``model_stage``",
        ),
    ],
}

TEXT_SUFFIXES = {".py", ".pyi", ".md", ".rst", ".txt", ".toml", ".cfg", ".ini", ".yml", ".yaml", ".sh"}
TEXT_NAMES = {"Makefile"}
SELF = "tools/rename_modules.py"


def _git(*args: str) -> str:
    return subprocess.run(["git", *args], check=True, capture_output=True, text=True).stdout


def _dotted(path: str) -> str:
    return path.removesuffix(".py").replace("/", ".")


def move_files(dry_run: bool) -> list[str]:
    """``git mv`` every row not done yet; the problems found (both names present, neither)."""
    problems = []
    for old, new in RENAMES:
        o, n = Path(old), Path(new)
        if o.exists() and n.exists():
            problems.append(f"{old} and {new} both exist: not moved")
        elif o.exists():
            print(f"git mv {old} {new}")
            if not dry_run:
                _git("mv", old, new)
        elif not n.exists():
            problems.append(f"{old}: missing, and {new} too")
    return problems


def _path_rule(old: str, new: str) -> tuple[re.Pattern[str], str] | None:
    """A file path of ``old`` in text: two or more of its trailing parts, ``.py`` or not."""
    parts = old.removesuffix(".py").split("/")
    if len(parts) < 2:
        return None
    # longest first: "rockyade/scene/generators/common", "scene/generators/common", ...
    alts = ["/".join(parts[i:]) for i in range(len(parts) - 1)]
    body = "|".join(re.escape(a) for a in alts)
    pattern = re.compile(rf"(?<![\w.\-])(?:[\w.\-]+/)*?({body})(\.py(?![\w])|(?![\w\-/])(?!\.[A-Za-z_]))")
    return pattern, new.removesuffix(".py")


def _replace_path(match: re.Match[str], new_stem: str) -> str:
    whole, found, ending = match.group(0), match.group(1), match.group(2)
    n = found.count("/") + 1
    new_found = "/".join(new_stem.split("/")[-n:])
    return whole[: match.start(1) - match.start(0)] + new_found + ending


def _from_import_rule(old: str) -> tuple[re.Pattern[str], str, str] | None:
    """``from rockyade.pkg import (... old ...)``: the statement, the old name, the new one."""
    if not old.startswith("rockyade/"):
        return None
    package, _, name = _dotted(old).rpartition(".")
    pattern = re.compile(
        rf"^([ \t]*from[ \t]+{re.escape(package)}[ \t]+import[ \t]+)(\([^)]*\)|[^\n]*(?:\\\n[^\n]*)*)",
        re.MULTILINE,
    )
    return pattern, name, ""


def _rewrite_import_names(names: str, old: str, new: str) -> str:
    """The list of ``from ... import`` names with ``old`` renamed (its alias kept, or given)."""

    def item(m: re.Match[str]) -> str:
        lead, name, alias = m.group(1), m.group(2), m.group(3)
        if name != old:
            return m.group(0)
        return f"{lead}{new}{alias if alias else f' as {old}'}"

    return re.sub(r"(^|[(,\s])([A-Za-z_]\w*)((?:[ \t]+as[ \t]+[A-Za-z_]\w*)?)(?=\s*(?:,|\)|$|\\|#))", item, names)


def rewrite_text(text: str, notes: list[str], path: Path | None = None) -> str:
    """``text`` (of the file ``path``) with every reference to an old module or file made to
    the new one."""
    is_python = path is None or path.suffix in (".py", ".pyi")
    for old, new in RENAMES:
        old_stem, new_stem = Path(old).stem, Path(new).stem
        if old.startswith("tests/"):
            text = re.sub(rf"(?<![\w]){re.escape(old_stem)}(?![\w])", new_stem, text)
            continue
        if old.startswith("docs/"):
            old_name, new_name = Path(old).name, Path(new).name
            text = re.sub(rf"(?<![\w\-]){re.escape(old_name)}(?![\w\-])", new_name, text)
            continue
        rule = _from_import_rule(old)
        if rule is not None:
            pattern, name, _ = rule
            new_name = _dotted(new).rpartition(".")[2]
            new_package = _dotted(new).rpartition(".")[0]

            def statement(m: re.Match[str], name: str = name, new_name: str = new_name, pkg: str = new_package) -> str:
                names = _rewrite_import_names(m.group(2), name, new_name)
                if names != m.group(2):
                    notes.append(f"from {pkg} import {name}: now {new_name} (aliased as before, or as {name})")
                return m.group(1) + names

            text = pattern.sub(statement, text)
        text = re.sub(rf"(?<![\w.]){re.escape(_dotted(old))}(?![\w])", _dotted(new), text)
        old_parts, new_parts = _dotted(old).split("."), _dotted(new).split(".")
        if not is_python:
            short_old, short_new = ".".join(old_parts[-2:]), ".".join(new_parts[-2:])
            text = re.sub(rf"(?<![\w.]){re.escape(short_old)}(?![\w])", short_new, text)
        if path is not None and path.as_posix() == str(Path(old).parent / "__init__.py"):
            text = re.sub(rf"(?<![\w`])``{re.escape(old_stem)}``(?![\w`])", f"``{new_stem}``", text)
        path_rule = _path_rule(old, new)
        if path_rule is not None:
            pattern, stem = path_rule
            text = pattern.sub(lambda m, s=stem: _replace_path(m, s), text)
    return text


def text_files() -> list[Path]:
    listed = _git("ls-files", "-co", "--exclude-standard", "-z").split("\0")
    return [
        Path(p)
        for p in listed
        if p and p != SELF and (Path(p).suffix in TEXT_SUFFIXES or Path(p).name in TEXT_NAMES) and Path(p).is_file()
    ]


def rewrite_files(dry_run: bool) -> tuple[list[str], list[Path]]:
    """Rewrite every text file; the literal edits not found, and the files changed."""
    missing = []
    changed = []
    for path in text_files():
        text = path.read_text(encoding="utf-8")
        notes: list[str] = []
        new = rewrite_text(text, notes, path)
        for old_text, new_text in LITERAL_EDITS.get(path.as_posix(), []):
            if new_text in new:
                continue  # done (a new text may start with its old one)
            if old_text in new:
                new = new.replace(old_text, new_text)
            else:
                missing.append(f"{path}: {old_text!r} not found (reworded?): check by hand")
        if new != text:
            print(f"rewrote {path}")
            for note in notes:
                print(f"  {note}")
            changed.append(path)
            if not dry_run:
                path.write_text(new, encoding="utf-8")
    return missing, changed


def tidy(paths: list[Path]) -> list[str]:
    """Sort the imports and format the Python files changed (longer names move lines), with
    ruff as the project configures it; the problems (ruff missing or failing)."""
    python = [str(p) for p in paths if p.suffix in (".py", ".pyi")]
    if not python:
        return []
    problems = []
    for args in (["check", "--select", "I", "--fix", "--quiet"], ["format", "--quiet"]):
        try:
            done = subprocess.run([sys.executable, "-m", "ruff", *args, *python], capture_output=True, text=True)
        except OSError as exc:
            return [f"ruff {args[0]} not run ({exc}): run it on the changed files"]
        if done.returncode != 0:
            problems.append(f"ruff {' '.join(args)}: {(done.stdout + done.stderr).strip()[:2000]}")
    return problems


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dry-run", action="store_true", help="print what would be done, change nothing")
    args = parser.parse_args(argv)
    if not Path("rockyade").is_dir() or not Path(".git").exists():
        parser.error("run from the repository root")
    problems = move_files(args.dry_run)
    missing, changed = rewrite_files(args.dry_run)
    problems += missing
    if not args.dry_run:
        problems += tidy(changed)
    for problem in problems:
        print(f"warning: {problem}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
