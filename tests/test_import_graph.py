"""The gate sees the house: no import cycle anywhere in the package (grimp, which import-linter
installs; ``make lint`` also keeps the ``acyclic_siblings`` contract of pyproject.toml), and
every module path docs/architecture.md names exists."""

from __future__ import annotations

import importlib
import re
import sys
from pathlib import Path

import grimp

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "rockyade"
#: Folders of the repository a path in the docs may start with (else it is inside the package).
TOP_FOLDERS = ("tests", "docs", "examples", "benchmarks", "tools")


def _cycles(graph: grimp.ImportGraph) -> list[list[str]]:
    """The import cycles of ``graph``: its strongly connected components of two modules or more
    (Tarjan's algorithm)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10_000))

    def visit(module: str) -> None:
        index[module] = low[module] = len(index)
        stack.append(module)
        on_stack.add(module)
        for imported in sorted(graph.find_modules_directly_imported_by(module)):
            if imported not in index:
                visit(imported)
                low[module] = min(low[module], low[imported])
            elif imported in on_stack:
                low[module] = min(low[module], index[imported])
        if low[module] == index[module]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == module:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for module in sorted(graph.modules):
        if module not in index:
            visit(module)
    return found


def test_no_module_of_the_package_imports_itself_back():
    """Any cycle, through any number of modules and across rooms (TYPE_CHECKING imports count:
    a cycle of types is a cycle of ideas)."""
    graph = grimp.build_graph("rockyade")
    assert _cycles(graph) == [], "import cycles (break each by moving what both need below both)"


def test_the_cycle_finder_sees_a_cycle():
    graph = grimp.ImportGraph()
    for module in ("p", "p.a", "p.b", "p.c"):
        graph.add_module(module)
    graph.add_import(importer="p.a", imported="p.b")
    graph.add_import(importer="p.b", imported="p.c")
    graph.add_import(importer="p.c", imported="p.a")
    assert _cycles(graph) == [["p.a", "p.b", "p.c"]]


def _named_paths(text: str) -> list[str]:
    """The module paths a document names in code spans: ``room/module``, ``room/``,
    ``module.py`` and ``rockyade.room.module`` (with, at its end, what the module defines)."""
    spans = re.findall(r"`([^`\s]+)`", text)
    return [s for s in spans if "/" in s or s.endswith(".py") or s.startswith("rockyade.")]


def _exists(name: str) -> bool:
    if "<" in name:
        return True  # a placeholder: solvers/<name>.py
    if name.startswith("rockyade."):
        parts = name.split("(")[0].split(".")
        for k in range(len(parts), 1, -1):
            try:
                module = importlib.import_module(".".join(parts[:k]))
            except ImportError:
                continue
            target: object = module
            for attr in parts[k:]:
                if not attr:
                    continue
                if not hasattr(target, attr):
                    return False
                target = getattr(target, attr)
            return True
        return False
    if name.startswith(("~", "$", ".", "-")) or "://" in name:
        return True  # a user's folder, a variable, a hidden file: not a module path
    if "/" not in name:
        return any(PACKAGE.rglob(name)) or (ROOT / name).exists() or any((ROOT / t).rglob(name) for t in TOP_FOLDERS)
    base = ROOT if name.split("/")[0] in (*TOP_FOLDERS, "rockyade") else PACKAGE
    path = name.rstrip("/")
    if "*" in path:
        return any(base.glob(path))
    if "." in path.split("/")[-1] and not path.endswith(".py"):  # tests/processes.require_yade
        module, _, _attr = path.rpartition(".")
        return (base / f"{module}.py").is_file()
    return (base / path).exists() or (base / f"{path}.py").is_file()


def test_every_module_path_docs_architecture_names_exists():
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    named = _named_paths(text)
    assert len(named) > 40  # the document names the rooms and their modules
    missing = sorted({name for name in named if not _exists(name)})
    assert missing == [], "docs/architecture.md names modules that do not exist"


def test_the_path_check_sees_a_missing_module():
    assert _exists("runner/journal") and _exists("runner/") and _exists("rockyade.runner.study_folder.StudyFolder")
    assert not _exists("runner/no_such_module") and not _exists("rockyade.runner.no_such_function")
    assert not _exists("studies/crosscheck_study.py")
