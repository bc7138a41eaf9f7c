"""The folder ``rockyade motion select`` writes, and reads back for ``rockyade assess --records``.

A selection is a folder that holds, as one result set replaced as a whole
(:mod:`rockyade.io.resultset`):

* the chosen record files, copied byte for byte from the engineer's folder (the selection
  stands alone: the records it names are beside it);
* ``selection.csv``: ``record`` (the file), ``scale_factor``, and after scaling ``pga_m_s2``,
  ``pga_g`` and, when T1 was given, ``sa_t1_m_s2`` and ``sa_t1_g`` (5 % damping);
* ``spectra.png``: each scaled record's spectrum, their mean, the site's spectrum and the band;
* ``selection.json`` (written last: it marks the set complete): the command, the site, the
  range, the rule, the bounds, the verdict and worst deviation, and each record's SHA-256.

Reading one back checks it: the JSON of a selection, every record in the CSV present beside it
(a regular file, not a link) with the SHA-256 the JSON gives, each factor finite and within
the bounds the JSON gives. A folder another command wrote is refused as ``--out``, and so is
a selection as ``--records`` of ``motion select``.
"""

from __future__ import annotations

import hashlib
import json
import math
import shutil
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from rockyade.errors import InputError

SELECTION_CSV = "selection.csv"
SELECTION_JSON = "selection.json"
SPECTRA_PNG = "spectra.png"
#: The set's fixed files; the JSON, last, marks it complete.
FIXED_FILES = (SELECTION_CSV, SPECTRA_PNG, SELECTION_JSON)
COMMAND = "rockyade motion select"


def sha256(path: Path) -> str:
    """The file's SHA-256, hex."""
    digest = hashlib.sha256()
    with path.open("rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            digest.update(chunk)
    return digest.hexdigest()


def is_selection(folder: str | Path) -> bool:
    """True when ``folder`` holds a selection's JSON."""
    return (Path(folder) / SELECTION_JSON).is_file()


def _previous_records(folder: Path) -> list[str]:
    """The record files of the selection already in ``folder`` (to be replaced with the set)."""
    try:
        data = json.loads((folder / SELECTION_JSON).read_text(encoding="utf-8"))
        return [str(r["file"]) for r in data.get("records", []) if "/" not in str(r["file"])]
    except (OSError, ValueError, KeyError, TypeError):
        return []


def check_out_folder(out: Path, records_folder: Path) -> None:
    """Refuse an ``--out`` that is a symbolic link, the records' folder, or holds files that are not a
    selection's.

    Raises
    ------
    InputError
        Naming ``--out``.
    """
    from rockyade.io.folders import refuse_link, refuse_other_files

    refuse_link(out, "--out")
    if out.exists() and not out.is_dir():
        raise InputError("--out", f"{out} is a file; give a folder")
    if out.exists() and records_folder.exists() and out.resolve() == records_folder.resolve():
        raise InputError("--out", "is the records' folder: give another folder for the selection")
    if out.is_dir():
        refuse_other_files(out, (*FIXED_FILES, *_previous_records(out)), "a selection", "motion select --out")


def write_selection(
    out: Path,
    sources: Sequence[Path],
    table: pd.DataFrame,
    meta: dict[str, Any],
    draw: Callable[[Path], None],
    shown: Sequence[str] | None = None,
) -> list[str]:
    """Write a selection into ``out`` as one result set (module docstring); the files written.

    Parameters
    ----------
    out
        The selection's folder (checked with :func:`check_out_folder`).
    sources
        The chosen record files, in the table's order.
    table
        ``selection.csv``'s rows (``record`` is each source's file name).
    meta
        ``selection.json``'s content (the records' SHA-256 are added here).
    draw
        Writes ``spectra.png`` at the path it is given.
    shown
        Each source as the user named it (its folder as given), for ``selection.json``
        (default: the source paths).
    """
    from rockyade.io.atomic import write_json
    from rockyade.io.folders import output_folder
    from rockyade.io.locking import output_lock
    from rockyade.io.resultset import replacing_set

    names = [Path(s).name for s in sources]
    if len(set(names)) != len(names):
        raise InputError("--records", "two chosen records have the same file name")
    clash = sorted(set(names) & set(FIXED_FILES))
    if clash:
        raise InputError("--records", f"a record is named {clash[0]}, a file of the selection itself: rename it")
    with output_folder(out), output_lock(out, "--out"):
        previous = _previous_records(out)
        with replacing_set(out, [*FIXED_FILES[:-1], *previous, *names, SELECTION_JSON], SELECTION_JSON) as stage:
            records = []
            for source, name, given in zip(sources, names, shown or [str(p) for p in sources], strict=True):
                shutil.copyfile(source, stage / name)
                records.append({"file": name, "sha256": sha256(stage / name), "source": given})
            with (stage / SELECTION_CSV).open("w", encoding="utf-8", newline="") as fh:
                table.to_csv(fh, index=False, float_format="%.8g", lineterminator="\n")
            draw(stage / SPECTRA_PNG)
            write_json(stage / SELECTION_JSON, {**meta, "command": COMMAND, "records": records})
    return [*names, SELECTION_CSV, SPECTRA_PNG, SELECTION_JSON]


@dataclass(frozen=True)
class SelectionFiles:
    """A selection read back (module docstring).

    Attributes
    ----------
    folder
        The selection's folder.
    files
        Its record files (absolute), in the CSV's order.
    scale_factors
        Each record's factor.
    meta
        ``selection.json``.
    """

    folder: Path
    files: tuple[str, ...]
    scale_factors: tuple[float, ...]
    meta: dict[str, Any]

    def summary(self) -> dict[str, Any]:
        """What ``assess`` reports of it: file, count, compatibility, worst deviation, site."""
        m = self.meta
        return {
            "selection": str(self.folder / SELECTION_CSV),
            "count": len(self.files),
            "compatible": m.get("compatible"),
            "worst_deviation": m.get("worst_deviation"),
            "worst_deviation_period_s": m.get("worst_deviation_period_s"),
            "period_range_s": m.get("period_range_s"),
            "rule": m.get("rule"),
            "site": m.get("site"),
        }


def read_selection(folder: str | Path, field: str = "--records") -> SelectionFiles:
    """Read a selection folder back, checked (module docstring).

    Raises
    ------
    InputError
        Naming ``field``: not a selection, a record missing, changed or a link, a factor out of range.
    """
    folder = Path(folder)
    try:
        meta = json.loads((folder / SELECTION_JSON).read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise InputError(field, f"{folder / SELECTION_JSON} cannot be read as a selection ({exc})") from None
    if not isinstance(meta, dict) or meta.get("command") != COMMAND:
        raise InputError(field, f"{folder / SELECTION_JSON} was not written by '{COMMAND}'")
    try:
        table = pd.read_csv(folder / SELECTION_CSV)
        files = [str(v) for v in table["record"]]
        factors = [float(v) for v in table["scale_factor"]]
        digests = {str(r["file"]): str(r["sha256"]) for r in meta["records"]}
        lo, hi = (float(v) for v in meta["scale_bounds"])
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise InputError(field, f"{folder} is not a complete selection ({type(exc).__name__}: {exc})") from None
    if not files or sorted(files) != sorted(digests):
        raise InputError(field, f"{SELECTION_CSV} and {SELECTION_JSON} of {folder} name different records")
    paths = []
    for name, factor in zip(files, factors, strict=True):
        path = folder / name
        if "/" in name or name.startswith(".") or path.is_symlink() or not path.is_file():
            raise InputError(field, f"{path}: the selection's record is missing (or not a regular file beside it)")
        if sha256(path) != digests[name]:
            raise InputError(field, f"{path} is not the record the selection chose (its SHA-256 differs): select again")
        if not (math.isfinite(factor) and lo <= factor <= hi):
            raise InputError(
                field, f"{name}'s scale factor {factor!r} is outside the selection's bounds [{lo:g}, {hi:g}]"
            )
        paths.append(str(path.resolve()))
    return SelectionFiles(folder, tuple(paths), tuple(factors), meta)


__all__ = [
    "COMMAND",
    "FIXED_FILES",
    "SELECTION_CSV",
    "SELECTION_JSON",
    "SPECTRA_PNG",
    "SelectionFiles",
    "check_out_folder",
    "is_selection",
    "read_selection",
    "sha256",
    "write_selection",
]
