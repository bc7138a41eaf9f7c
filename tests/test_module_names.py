"""A module's name says what it is on its own: no two modules of the package share a basename,
but for the same role in sibling packages, which each say so in their docstring.

The rule for the command line: a command module of ``cli/`` is named after the command it
implements (``cli/verify.py`` is ``rockyade verify``), or after what a few related commands are
about (:data:`COMMAND_GROUPS`), and its docstring opens with them; a module anywhere else is
named after what it holds (``studies/verification.py``, ``figures/verification_histories.py``),
so the two never meet.
"""

from __future__ import annotations

import ast
import re
from collections import defaultdict
from pathlib import Path

import rockyade

PACKAGE = Path(rockyade.__file__).parent

#: Basenames that name the same role in sibling packages: each engine that runs in another
#: Python (YADE's, Debian's python3-siconos) has a JSON payload, a driver that Python runs and
#: a backend that runs the driver (docs/architecture.md, "How to add a solver").
SAME_ROLE: dict[str, set[str]] = {
    "payload.py": {"yade", "siconos"},
    "driver.py": {"yade", "siconos"},
    "backend.py": {"yade", "siconos"},
}

#: Command modules named after what their commands are about, not after one of them.
COMMAND_GROUPS: dict[str, str] = {
    "blocks": "params and calibrate: a block's parameters",
    "studies": "compare, batch and paper: many runs",
}

#: Names every package has.
PACKAGE_FILES = {"__init__.py", "__main__.py"}


def _modules_by_basename() -> dict[str, list[Path]]:
    found: dict[str, list[Path]] = defaultdict(list)
    for path in sorted(PACKAGE.rglob("*.py")):
        if path.name not in PACKAGE_FILES:
            found[path.name].append(path.relative_to(PACKAGE))
    return found


def test_no_two_modules_share_a_basename():
    shared = []
    for name, paths in _modules_by_basename().items():
        if len(paths) < 2:
            continue
        rooms = {p.parent.as_posix() for p in paths}
        if rooms <= SAME_ROLE.get(name, set()):
            continue
        shared.append(f"{name}: {', '.join(p.as_posix() for p in paths)}")
    assert not shared, (
        "modules that share a basename (name each after what it holds; or, for the same role in "
        "sibling packages, add them to SAME_ROLE and say so in their docstrings):\n  " + "\n  ".join(shared)
    )


def test_same_role_modules_name_their_siblings():
    """Each module of a same-role set names the others in its docstring (``rockyade.siconos.driver``
    in ``yade/driver.py``), so a reader who opens one knows the others exist and match."""
    missing = []
    for name, rooms in SAME_ROLE.items():
        for room in sorted(rooms):
            path = PACKAGE / room / name
            if not path.exists():
                missing.append(f"{room}/{name}: listed in SAME_ROLE but missing")
                continue
            doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8"))) or ""
            for other in sorted(rooms - {room}):
                dotted = f"rockyade.{other}.{name.removesuffix('.py')}"
                if dotted not in doc:
                    missing.append(f"{room}/{name}: its docstring does not name {dotted}")
    assert not missing, "\n".join(missing)


def test_command_modules_are_named_after_their_commands():
    from rockyade.cli import COMMAND_MODULES

    wrong = []
    for dotted in COMMAND_MODULES:
        name = dotted.rsplit(".", 1)[1]
        doc = ast.get_docstring(ast.parse((PACKAGE / "cli" / f"{name}.py").read_text(encoding="utf-8"))) or ""
        commands = re.findall(r"``rockyade ([a-z][a-z-]*)", doc.split("\n\n")[0])
        if not commands:
            wrong.append(f"cli/{name}.py: its docstring does not open with the commands it implements")
        elif name.replace("_", "-") not in commands and name not in COMMAND_GROUPS:
            wrong.append(
                f"cli/{name}.py implements {', '.join(commands)}: name it after one, or list it in COMMAND_GROUPS"
            )
    assert not wrong, "\n".join(wrong)
