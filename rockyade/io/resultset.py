"""A set of result files replaced as a whole or not at all.

A command whose answer is several files (``fragility``: ``runs.csv``, ``stripes.csv``,
``records.csv``, ``fragility.json``, ``fragility.png``) writes the new set in a temporary
folder beside them (``.set.<random>.tmp``); a full disk, an error or Ctrl-C while it is
written leaves the previous set untouched and the temporary folder removed. The set then
goes in by renames only (no space needed), in an order that never shows a mixed set:

1. the staged folder is renamed ``.set.commit`` (the commit point), with the list of its
   files in ``.names``;
2. the set's *last* file (the JSON that marks a set complete) of the old set is removed:
   from here no complete set is visible;
3. the new files but the last are renamed in; files of the old set that the new one lacks
   are removed;
4. the new last file is renamed in: the new set is complete.

A process killed between 1 and 4 leaves ``.set.commit``: :func:`settle` (called by the next
writer, under the folder's lock) finishes the swap; an uncommitted ``.set.*.tmp`` is removed.
So the folder holds the previous complete set, the new complete set, or (killed between 2
and 4, before the next writer settles it) an incomplete one without its last file: never a
mix that looks complete.
"""

from __future__ import annotations

import contextlib
import functools
import os
import secrets
import shutil
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

from rockyade.io.atomic import fsync_dir

#: The committed set's folder, and the list of its files in it.
COMMIT_DIR = ".set.commit"
NAMES_FILE = ".names"
STAGE_PREFIX = ".set."
STAGE_SUFFIX = ".tmp"


@contextlib.contextmanager
def replacing_set(folder: str | os.PathLike[str], names: Sequence[str], last: str) -> Iterator[Path]:
    """Yield an empty temporary folder beside the set; on success swap what was written
    there in for the set (module docstring); on failure remove it and leave the set as it was.

    Parameters
    ----------
    folder
        The set's folder (exists; the caller holds its lock).
    names
        Every file a set may have (an old one the new set lacks is removed at the swap).
    last
        The file that marks a set complete; the new set must have it.
    """
    folder = Path(folder)
    settle(folder, names, last)
    stage = folder / f"{STAGE_PREFIX}{secrets.token_hex(8)}{STAGE_SUFFIX}"
    stage.mkdir()
    try:
        yield stage
        written = sorted(p.name for p in stage.iterdir())
        if last not in written:
            raise ValueError(f"the new set has no {last}")
        _named(functools.partial((stage / NAMES_FILE).write_text, "\n".join(written) + "\n"), stage / NAMES_FILE)
        for name in written:
            _named(functools.partial(_fsync, stage / name), stage / name)
        fsync_dir(stage)
        os.rename(stage, folder / COMMIT_DIR)  # the commit point
        fsync_dir(folder)
    except OSError as exc:
        shutil.rmtree(stage, ignore_errors=True)
        if exc.filename and Path(exc.filename).parent == stage:  # named as the file of the set it would be
            exc.filename = str(folder / Path(exc.filename).name)
        raise
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        raise
    _finish(folder, names, last)


def settle(folder: str | os.PathLike[str], names: Sequence[str], last: str) -> None:
    """Finish a swap a killed writer committed; remove the sets it only staged.

    Parameters
    ----------
    folder, names, last
        As :func:`replacing_set` takes them.
    """
    folder = Path(folder)
    for stage in folder.glob(f"{STAGE_PREFIX}*{STAGE_SUFFIX}"):
        if stage.is_dir() and not stage.is_symlink():
            shutil.rmtree(stage, ignore_errors=True)
    commit = folder / COMMIT_DIR
    if commit.is_dir() and not commit.is_symlink():
        _finish(folder, names, last)


def _finish(folder: Path, names: Sequence[str], last: str) -> None:
    """Steps 2 to 4 of the module docstring; each step can be done again (a killed swap)."""
    commit = folder / COMMIT_DIR
    new = set((commit / NAMES_FILE).read_text().split())
    if (commit / last).exists():  # the new set is not in: the last file there is the old one's
        with contextlib.suppress(FileNotFoundError):
            (folder / last).unlink()
    for name in sorted(new - {last}):
        if (commit / name).exists():
            os.replace(commit / name, folder / name)
    for name in names:
        if name not in new:
            with contextlib.suppress(FileNotFoundError):
                (folder / name).unlink()
    if (commit / last).exists():
        os.replace(commit / last, folder / last)
    fsync_dir(folder)
    shutil.rmtree(commit, ignore_errors=True)


def _named(step: Callable[[], object], path: Path) -> None:
    """Do ``step``; an OSError that names no file (a full disk's) names ``path``."""
    try:
        step()
    except OSError as exc:
        if exc.filename is None:
            exc.filename = str(path)
        raise


def _fsync(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


__all__ = ["replacing_set", "settle"]
