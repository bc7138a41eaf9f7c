"""Finished runs written as they end, so that a study stopped at any point resumes without
repeating or duplicating a run: the one resume mechanism of every command that runs many runs
(``batch``, ``fragility``, ``assess``, ``uncertainty``).

A run's record is ``<folder>/<name>.json``: its metadata with ``status``, ``scene_hash`` and
``summary`` (the study's row of the run). It is written atomically and fsynced, file and
folder (:func:`rockyade.io.atomic.write_json`), as the run ends: Ctrl-C, kill -9 or a power
cut leaves whole records or none. A record counts on resume when its ``status`` is
``completed`` or ``overturned`` and its ``scene_hash`` is the run's (a failed run is run again).

A :class:`Journal` adds the study's identity (``study.json``: the command and the options
that decide its runs): ``resume`` over a folder written by another study or with other
options is refused (:class:`~rockyade.errors.InputError` naming ``--resume``); without
``resume`` an earlier journal is cleared. ::

    journal = Journal(out / "partial", {"command": "fragility", ...}, resume=args.resume)
    row = journal.done(name, scene_hash)        # the row of a finished run, or None
    journal.record(name, meta_with_summary)     # as each run ends (in the main process)
"""

from __future__ import annotations

import contextlib
import json
import shutil
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from rockyade.errors import InputError
from rockyade.io.atomic import json_text, remove_stale_temporaries, write_json

#: Statuses of a run that resume keeps (a failed run is run again).
KEPT_STATUSES = ("completed", "overturned")
#: The study's identity in a journal's folder.
IDENTITY_FILE = "study.json"


def write_run(folder: str | Path, name: str, record: Mapping[str, Any], durable: bool = True) -> None:
    """Write a run's record ``<folder>/<name>.json`` atomically (``durable``: fsynced).

    Parameters
    ----------
    folder
        The runs' folder (made if missing).
    name
        The run's name (file stem).
    record
        Its metadata: ``status``, ``scene_hash`` and ``summary`` (the row) at least.
    """
    write_json(Path(folder) / f"{name}.json", marked_record(record), durable=durable)


#: The key of a record that names the row's numbers that were not finite (strict JSON has
#: them as null): row key -> ``"nan"``, ``"inf"`` or ``"-inf"``.
NOT_FINITE_KEY = "summary_not_finite"


def marked_record(record: Mapping[str, Any]) -> dict[str, Any]:
    """``record`` with :data:`NOT_FINITE_KEY` when its ``summary`` row has numbers that are not
    finite (:func:`write_run` writes it so; a run's Result that carries its row is written so).

    Parameters
    ----------
    record
        A run's record (its ``summary``: the row).
    """
    out = dict(record)
    summary = out.get("summary")
    if isinstance(summary, Mapping):
        odd = {
            k: repr(float(v)) for k, v in summary.items() if isinstance(v, float | np.floating) and not np.isfinite(v)
        }
        if odd:
            out[NOT_FINITE_KEY] = odd
    return out


def summary_row(record: Mapping[str, Any]) -> dict[str, Any]:
    """The summary row of a run's record as it was written: a record is strict JSON
    (:mod:`rockyade.io.strict_json`: NaN and infinity as null), and the record names which of
    the row's nulls were NaN or infinite (:data:`NOT_FINITE_KEY`); a null it does not name was
    None (a record written before it named them: its NaN tokens read back as NaN).

    Parameters
    ----------
    record
        The record as read (with a ``summary`` mapping).
    """
    row = dict(record["summary"])
    odd = record.get(NOT_FINITE_KEY)
    if isinstance(odd, Mapping):
        for key, text in odd.items():
            if key in row and row[key] is None and text in ("nan", "inf", "-inf"):
                row[key] = float(text)
    return row


def read_run(folder: str | Path, name: str, scene_hash: str) -> dict[str, Any] | None:
    """The summary row of run ``name`` if its record says it completed (or overturned) for
    ``scene_hash``; None otherwise (no record, unreadable, failed, another scene).

    The row reads back as it was written (:func:`summary_row`: its numbers that were not
    finite, written as null, are NaN or infinite again).

    Parameters
    ----------
    folder
        The runs' folder.
    name
        The run's name.
    scene_hash
        The scene the run must be of.
    """
    path = Path(folder) / f"{name}.json"
    if path.is_symlink() or not path.is_file():
        return None
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(data, dict) or not isinstance(data.get("summary"), dict):
        return None
    if data.get("status") in KEPT_STATUSES and data.get("scene_hash") == scene_hash:
        return summary_row(data)
    return None


def claim(folder: str | Path, identity: Mapping[str, Any], resume: bool, field: str = "--resume") -> dict[str, Any]:
    """Write the study's identity (``<folder>/study.json``); with ``resume``, first refuse a
    folder whose identity is another's. The identity as it reads back from the file.

    Parameters
    ----------
    folder
        The runs' folder (made if missing).
    identity
        What decides the study's runs (JSON-ready).
    resume
        The caller keeps the runs there.
    field
        The option named when the resume is refused.

    Raises
    ------
    InputError
        ``resume`` over a folder written by another study or with other options.
    """
    folder = Path(folder)
    ident = json.loads(json_text(dict(identity)))
    path = folder / IDENTITY_FILE
    if resume and path.is_file():
        try:
            earlier = json.loads(path.read_text())
        except (OSError, ValueError):
            earlier = None
        if earlier != ident:
            why = _differences(earlier, ident)
            raise InputError(
                field,
                f"{folder} holds the runs of another study or other options ({why}); "
                "run the command as it was run, or without --resume to start again",
            )
    folder.mkdir(parents=True, exist_ok=True)
    write_json(path, ident)
    return ident


class Journal:
    """The finished runs of one study in ``folder`` (module docstring).

    Parameters
    ----------
    folder
        Where the records and ``study.json`` go (made if missing; the caller holds the
        lock of the output it is in).
    identity
        What decides the study's runs (JSON-ready): the command, its options, the scene's hash.
    resume
        Keep the records of an earlier run of the same study (refused for another study);
        False: clear them.
    field
        The option named when a resume is refused.

    Raises
    ------
    InputError
        ``resume`` over a journal written by another study or with other options.
    """

    def __init__(self, folder: str | Path, identity: Mapping[str, Any], resume: bool, field: str = "--resume") -> None:
        self.folder = Path(folder)
        self.resumed = 0
        if not resume:
            self.clear()
        self.identity = claim(self.folder, identity, resume, field)
        remove_stale_temporaries(self.folder)

    def done(self, name: str, scene_hash: str) -> dict[str, Any] | None:
        """The row of a run finished earlier (:func:`read_run`), counted in ``resumed``."""
        row = read_run(self.folder, name, scene_hash)
        if row is not None:
            self.resumed += 1
        return row

    def record(self, name: str, record: Mapping[str, Any]) -> None:
        """Write a finished run's record, durably (:func:`write_run`)."""
        write_run(self.folder, name, record)

    def clear(self) -> None:
        """Remove the journal (its folder and what is in it)."""
        if self.folder.is_symlink():
            self.folder.unlink()
        elif self.folder.is_dir():
            shutil.rmtree(self.folder)

    def remove_if_empty(self) -> None:
        """Remove the journal if it holds no run (only its identity): nothing to resume."""
        records = [p for p in self.folder.glob("*.json") if p.name != IDENTITY_FILE]
        if not records:
            with contextlib.suppress(OSError):
                self.clear()


def _differences(earlier: Any, now: Mapping[str, Any]) -> str:
    """What differs between two identities, in a few words."""
    if not isinstance(earlier, dict):
        return "its study.json is unreadable"
    keys = sorted(k for k in {*earlier, *now} if earlier.get(k) != now.get(k))
    if earlier.get("command") != now.get("command"):
        return f"written by '{earlier.get('command')}', not '{now.get('command')}'"
    shown = ", ".join(f"{k}: {earlier.get(k)!r} then, {now.get(k)!r} now" for k in keys[:3])
    return shown or "unknown"


__all__ = [
    "IDENTITY_FILE",
    "KEPT_STATUSES",
    "NOT_FINITE_KEY",
    "Journal",
    "claim",
    "marked_record",
    "read_run",
    "summary_row",
    "write_run",
]
