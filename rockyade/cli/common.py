"""Helpers shared by the command modules (standard library only: the parser stays fast)."""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import Any

from rockyade.errors import InputError

#: The solvers' names, as :func:`rockyade.solvers.solver_names` lists them (kept here so that
#: building the parser does not import the solvers; a test checks the two agree).
SOLVER_NAMES: tuple[str, ...] = ("housner", "reference", "yade")


def json_out(data: Any) -> None:
    """Print ``data`` as indented, sorted JSON (numpy values converted)."""
    from rockyade.io.atomic import json_text

    print(json_text(data))


def print_wrote(path: Path, json_mode: bool = False) -> None:
    """``wrote PATH`` on stdout, or on stderr after ``--json`` (stdout stays one JSON document)."""
    import sys

    print(f"wrote {path}", file=sys.stderr if json_mode else sys.stdout)


def add_allow_large(p: argparse.ArgumentParser) -> None:
    """``--allow-large``: run above the documented cost limits (docs/reliability.md)."""
    p.add_argument(
        "--allow-large",
        action="store_true",
        help="run even when the cost estimate (integration steps, samples, memory) is above the "
        "documented limits",
    )


def check_output_dir(path: Path, option: str) -> None:
    """Refuse an output directory that cannot be created or written (InputError naming
    ``option``, e.g. ``out`` or ``--out``), before any work; nothing is created here."""
    option = _flag(option)
    if path.is_file():
        raise InputError(option, f"{path} is a file; give a directory")
    _check_dir(path, option, f"cannot write into {path}")


def check_output_file(path: Path, option: str, suffix: str | tuple[str, ...] | None = None) -> None:
    """Refuse an output file whose folder cannot be created or written, or (``suffix``, e.g.
    ``".png"`` or ``(".toml", ".json")``) whose name does not end as the file it will be (no
    scene overwritten by a plot)."""
    option = _flag(option)
    if path.is_dir():
        raise InputError(option, f"{path} is a directory; give a file name")
    suffixes = (suffix,) if isinstance(suffix, str) else suffix
    if suffixes is not None and path.suffix.lower() not in suffixes:
        raise InputError(option, f"must be a {' or '.join(suffixes)} file, got {path}")
    _check_dir(path.parent if str(path.parent) else Path("."), option, f"cannot write {path}")


def _flag(option: str) -> str:
    """The option as typed on the command line: ``out`` -> ``--out``."""
    return option if option.startswith("-") else "--" + option.replace("_", "-")


def _check_dir(path: Path, option: str, what: str) -> None:
    existing = path
    while not existing.exists():
        if existing.parent == existing:
            break
        existing = existing.parent
    if existing.exists() and not existing.is_dir():
        raise InputError(option, f"{what}: {existing} is not a directory")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise InputError(option, f"{what}: {existing} is not writable")


def total_time(args: argparse.Namespace) -> float:
    """Seconds since the command line started (imports of the command included)."""
    import time

    start = getattr(args, "started_at", None)
    return time.perf_counter() - start if start is not None else float("nan")
