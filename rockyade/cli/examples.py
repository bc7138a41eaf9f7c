"""``rockyade examples --out DIR``: copy the example scenes, studies and records out of the
installed package (the wheel carries the repository's ``examples/`` as ``rockyade/examples``;
a checkout reads its ``examples/`` folder), so that a pip-installed user can run them.

The copy never follows a symlink (neither in the package nor at the destination), refuses an
existing non-empty ``DIR`` unless ``--force``, and is atomic: a new ``DIR`` appears complete
(the files are written into a temporary sibling folder that is renamed into place); with
``--force`` into an existing folder, each file is replaced atomically.
"""

from __future__ import annotations

import argparse
import os
import shutil
import stat
import tempfile
from pathlib import Path

from rockyade.cli.common import Commands, add_command
from rockyade.errors import InputError, RockyadeError
from rockyade.io.atomic import atomic_open, fsync_dir

#: Names that are never copied (caches, compiled files, output folders of the gallery scripts).
SKIPPED = ("__pycache__", ".ipynb_checkpoints")
SKIPPED_SUFFIXES = (".pyc", ".pyo")


def examples_root() -> Path:
    """The folder of the examples: ``rockyade/examples`` in an installed wheel, or the
    checkout's ``examples/`` (an editable install)."""
    package = Path(__file__).resolve().parent.parent
    for candidate in (package / "examples", package.parent / "examples"):
        if candidate.is_dir() and not candidate.is_symlink():
            return candidate
    raise RockyadeError(f"the examples are not installed with this copy of rockyade (looked in {package / 'examples'})")


def example_files(root: Path) -> list[Path]:
    """The regular files under ``root``, relative to it, sorted; symlinks and caches are left out."""
    found: list[Path] = []
    for folder, dirs, files in os.walk(root, followlinks=False):
        base = Path(folder)
        dirs[:] = sorted(d for d in dirs if d not in SKIPPED and not (base / d).is_symlink())
        for name in sorted(files):
            path = base / name
            if name.endswith(SKIPPED_SUFFIXES) or name in SKIPPED:
                continue
            if stat.S_ISREG(path.lstat().st_mode):
                found.append(path.relative_to(root))
    return found


def _refuse_links(out: Path, relative: list[Path]) -> None:
    """Refuse a destination that is, or holds where a file goes, a symlink (InputError on ``out``)."""
    if out.is_symlink():
        raise InputError("out", f"{out} is a symlink; give a real folder")
    for rel in relative:
        path = out
        for part in rel.parts:
            path = path / part
            if path.is_symlink():
                raise InputError("out", f"{path} is a symlink; nothing is written through a symlink")


def _copy_into(root: Path, relative: list[Path], target: Path) -> None:
    for rel in relative:
        dest = target / rel
        if dest.parent != target and not dest.parent.is_dir():
            dest.parent.mkdir(parents=True, exist_ok=True)
        with (root / rel).open("rb") as src, atomic_open(dest, "wb") as fh:
            shutil.copyfileobj(src, fh)


def write_examples(out: Path, force: bool = False) -> list[Path]:
    """Copy the examples into ``out``; returns the written files, relative to ``out``.

    Parameters
    ----------
    out
        The destination folder: new, empty, or (``force``) an existing folder whose files of
        the same names are replaced.
    force
        Write into an existing non-empty folder.
    """
    root = examples_root()
    relative = example_files(root)
    _refuse_links(out, relative)
    if out.exists() and not out.is_dir():
        raise InputError("out", f"{out} is a file; give a folder")
    existing = out.is_dir() and any(out.iterdir())
    if existing and not force:
        raise InputError("out", f"{out} exists and is not empty; give a new folder or pass --force")
    if existing:
        _copy_into(root, relative, out)
        return relative
    out.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".partial", dir=out.parent))
    try:
        _copy_into(root, relative, staging)
        os.chmod(staging, 0o777 & ~_umask())
        os.replace(staging, out)  # onto a missing or empty folder: the folder appears complete
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    fsync_dir(out.parent)
    return relative


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def cmd_examples(args: argparse.Namespace) -> int:
    """copy the example scenes, studies and records into a folder

    Copy the example scenes (single blocks, assemblies), studies and ground-motion records shipped with rockyade into
    DIR, listing each file written. DIR must be new or empty unless --force; a new DIR appears complete or not at all;
    nothing is written through a symlink.
    """
    out: Path = args.out
    written = write_examples(out, force=args.force)
    for rel in written:
        print(out / rel)
    print(f"wrote {len(written)} files into {out}; run one with: rockyade run {out / 'specimen1_free.toml'}")
    return 0


def register(sub: Commands) -> None:
    """Add ``rockyade examples``."""
    p = add_command(sub, cmd_examples)
    p.add_argument("--out", type=Path, required=True, metavar="DIR", help="destination folder")
    p.add_argument("--force", action="store_true", help="write into an existing non-empty folder, replacing files")
