"""An output folder made for a command that is removed again when the command fails before
it wrote anything (no empty ``--out`` after an error or Ctrl-C)."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterable, Iterator
from pathlib import Path

from rockyade.errors import InputError

#: What a command leaves in a folder it has not written a result to yet: its lock, and the
#: study's identity in an otherwise empty runs folder.
BOOKKEEPING = (".rockyade.lock", "study.json")


@contextlib.contextmanager
def output_folder(path: str | os.PathLike[str]) -> Iterator[bool]:
    """Make ``path`` (and its parents) if missing; yield whether it was made here. On any
    exception a folder made here that holds nothing but bookkeeping (:data:`BOOKKEEPING`,
    in it or in empty sub-folders) is removed, and the exception goes on.

    Parameters
    ----------
    path
        The output folder.
    """
    out = Path(path)
    created = not out.exists()
    out.mkdir(parents=True, exist_ok=True)
    try:
        yield created
    except BaseException:
        if created:
            with contextlib.suppress(OSError):
                remove_if_unused(out)
        raise


def remove_if_unused(folder: Path) -> bool:
    """Remove ``folder`` if it holds only bookkeeping files and empty folders (never following
    a link); whether it was removed."""
    entries = list(folder.iterdir())
    for entry in entries:
        if entry.is_symlink():
            return False
        if entry.is_dir():
            if not remove_if_unused(entry):
                return False
        elif entry.name not in BOOKKEEPING:
            return False
    for entry in folder.iterdir():
        entry.unlink()
    folder.rmdir()
    return True


def other_files(folder: Path, names: Iterable[str]) -> list[str]:
    """The entries of ``folder`` (an existing directory) that are not ``names`` of a command's set
    nor bookkeeping: neither :data:`BOOKKEEPING` nor hidden (a set being swapped in); sorted. What a
    command refuses to write its set beside (it would be mixed with another's)."""
    known = set(names) | set(BOOKKEEPING)
    return sorted(p.name for p in folder.iterdir() if p.name not in known and not p.name.startswith("."))


def refuse_link(path: Path, field: str) -> None:
    """Refuse ``path`` when it is a symbolic link, dangling or not: rockyade writes nothing through
    a link (InputError naming ``field``)."""
    if path.is_symlink():
        what = "a symbolic link to nothing" if not path.exists() else "a symbolic link"
        raise InputError(field, f"{path} is {what}; give a real folder (rockyade writes nothing through a link)")


def refuse_other_files(folder: Path, names: Iterable[str], what: str, writer: str, field: str = "--out") -> None:
    """Refuse a ``folder`` that holds files besides ``names`` (:func:`other_files`): a set written
    there would be mixed with them. Nothing to refuse where ``folder`` is not a directory yet.

    Parameters
    ----------
    folder, names
        The folder and every file its set may hold.
    what, writer
        The set in words ("a fragility study") and the command that writes it ("fragility --out").
    field
        The option that names ``folder``.

    Raises
    ------
    InputError
        Naming ``field`` and the first five files that are not the set's.
    """
    if not folder.is_dir():
        return
    others = other_files(folder, names)
    if others:
        shown = ", ".join(others[:5]) + (" ..." if len(others) > 5 else "")
        raise InputError(
            field,
            f"{folder} holds files that are not {what}'s ({shown}): give an empty folder, or one a previous "
            f"'{writer}' wrote (its set is then replaced as a whole)",
        )


__all__ = ["BOOKKEEPING", "other_files", "output_folder", "refuse_link", "refuse_other_files", "remove_if_unused"]
