"""Finished runs written as they end, so that a study stopped at any point resumes without
repeating or duplicating a run: the one resume mechanism of every study (``batch``,
``fragility``, ``assess``, ``crosscheck``, ``uncertainty``), kept in its output folder
(:class:`rockyade.runner.study_folder.StudyFolder`).

A run's record is ``<folder>/<name>.json``: its metadata with ``status``, ``scene_hash``,
``summary`` (the study's row of the run, :meth:`rockyade.runner.rows.RunRow.summary`) and, when
the study asks for one, its collapse ``verdict``. It is written atomically and fsynced, file
and folder (:func:`rockyade.io.atomic.write_json`), as the run ends: Ctrl-C, kill -9 or a power
cut leaves whole records or none. A record is sealed as results are: ``record_sha256`` is the
SHA-256 of what resume reads (status, scene hash, row and verdict), so a record edited by hand
(into valid JSON, say) or damaged is not trusted: its run is run again, and the study says so.
A record counts on resume when it is sealed, its ``status`` is ``completed`` or ``overturned``
and its ``scene_hash`` is the run's (a failed run is run again).

A :class:`Journal` adds the study's identity (``study.json``: the command and the options
that decide its runs): ``resume`` over a folder written by another study or with other
options is refused (:class:`~rockyade.errors.InputError` naming ``--resume`` and the option
that changed); without ``resume`` an earlier journal is cleared (unless the journal is a
study's result, as a batch's ``runs/``). ::

    journal = Journal(out / "partial", {"command": "fragility", ...}, resume=args.resume)
    row = journal.done(name, scene_hash)        # the row of a run finished earlier, or None
    journal.record(name, meta_with_summary)     # as each run ends (in the main process)
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import shutil
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rockyade.errors import InputError
from rockyade.io.atomic import json_text, remove_stale_temporaries, write_json
from rockyade.runner.rows import ANSWERED, Cell, Cells

#: Statuses of a run that resume keeps (a failed run is run again).
KEPT_STATUSES = ANSWERED
#: The study's identity in a journal's folder.
IDENTITY_FILE = "study.json"
#: The key of a record that names the row's numbers that were not finite (strict JSON has
#: them as null): row key -> ``"nan"``, ``"inf"`` or ``"-inf"``.
NOT_FINITE_KEY = "summary_not_finite"
#: The key of a record's seal: the SHA-256 of what resume reads (module docstring).
SEAL_KEY = "record_sha256"
#: What a record's seal covers.
SEALED_KEYS = ("status", "scene_hash", "summary", "verdict", NOT_FINITE_KEY)
#: A record as read or written: JSON-ready mappings.
Record = Mapping[str, object]


def write_run(folder: str | Path, name: str, record: Record, durable: bool = True) -> None:
    """Write a run's record ``<folder>/<name>.json`` atomically (``durable``: fsynced), sealed.

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


def marked_record(record: Record) -> dict[str, object]:
    """``record`` as it is written: with :data:`NOT_FINITE_KEY` when its ``summary`` row has
    numbers that are not finite, and sealed (:data:`SEAL_KEY`). :func:`write_run` writes it so;
    a run's Result that carries its row is written so.

    Parameters
    ----------
    record
        A run's record (its ``summary``: the row).
    """
    out = {k: v for k, v in record.items() if k not in (NOT_FINITE_KEY, SEAL_KEY)}
    summary = out.get("summary")
    if isinstance(summary, Mapping):
        odd = {
            k: repr(float(v)) for k, v in summary.items() if isinstance(v, float | np.floating) and not np.isfinite(v)
        }
        if odd:
            out[NOT_FINITE_KEY] = odd
    out[SEAL_KEY] = seal(json.loads(json_text(out)))
    return out


def seal(record: Mapping[str, object]) -> str:
    """The SHA-256 of what resume reads of a record as it is on disk (strict JSON: the keys of
    :data:`SEALED_KEYS`, in a canonical text)."""
    payload = {k: record[k] for k in SEALED_KEYS if k in record}
    text = json.dumps(payload, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode()).hexdigest()


def summary_row(record: Record) -> Cells:
    """The summary row of a run's record as it was written: a record is strict JSON
    (:mod:`rockyade.io.strict_json`: NaN and infinity as null), and the record names which of
    the row's nulls were NaN or infinite (:data:`NOT_FINITE_KEY`); a null it does not name was
    None.

    Parameters
    ----------
    record
        The record as read (with a ``summary`` mapping).
    """
    summary = record["summary"]
    assert isinstance(summary, Mapping)
    row: Cells = dict(summary)
    odd = record.get(NOT_FINITE_KEY)
    if isinstance(odd, Mapping):
        for key, text in odd.items():
            if key in row and row[key] is None and text in ("nan", "inf", "-inf"):
                row[key] = float(text)
    return row


@dataclass(frozen=True)
class Found:
    """A run finished earlier, as its record says.

    Attributes
    ----------
    summary
        Its row as written (:func:`summary_row`).
    verdict
        Its collapse verdict as written (None: the study asked for none).
    """

    summary: Cells
    verdict: Mapping[str, object] | None


#: What :func:`find_run` says of a record whose seal does not match.
DAMAGED = "damaged"


def find_run(folder: str | Path, name: str, scene_hash: str) -> Found | str | None:
    """Run ``name`` as its record in ``folder`` says, if it answered for ``scene_hash``;
    :data:`DAMAGED` when the record is there but not sealed as written (edited, or damaged);
    None otherwise (no record, unreadable, failed, another scene)."""
    path = Path(folder) / f"{name}.json"
    if path.is_symlink() or not path.is_file():
        return None
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return DAMAGED if path.stat().st_size else None
    if not isinstance(data, dict) or not isinstance(data.get("summary"), dict):
        return DAMAGED
    if data.get(SEAL_KEY) != seal(data):
        return DAMAGED
    if data.get("status") not in KEPT_STATUSES or data.get("scene_hash") != scene_hash:
        return None
    verdict = data.get("verdict")
    return Found(summary_row(data), verdict if isinstance(verdict, dict) else None)


def read_run(folder: str | Path, name: str, scene_hash: str) -> Cells | None:
    """The summary row of run ``name`` if its sealed record says it completed (or overturned)
    for ``scene_hash``; None otherwise (no record, unreadable, edited, failed, another scene).

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
    found = find_run(folder, name, scene_hash)
    return found.summary if isinstance(found, Found) else None


def read_identity(path: Path) -> dict[str, object] | None:
    """A study's identity as written (None: missing, unreadable, not an identity)."""
    if path.is_symlink() or not path.is_file():
        return None
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def claim(
    folder: str | Path,
    identity: Mapping[str, object],
    resume: bool,
    field: str = "--resume",
    *,
    path: Path | None = None,
    option_name: Callable[[str], str] | None = None,
) -> dict[str, object]:
    """Write the study's identity (``<folder>/study.json``, or ``path``); with ``resume``, first
    refuse a folder whose identity is another's. The identity as it reads back from the file.

    Parameters
    ----------
    folder
        The runs' folder (named in errors).
    identity
        What decides the study's runs (JSON-ready).
    resume
        The caller keeps the runs there.
    field
        The option named when the resume is refused.
    path
        Where the identity goes (default ``<folder>/study.json``).
    option_name
        The option a key of the identity stands for (default: ``options.tail`` is ``--tail``).

    Raises
    ------
    InputError
        ``resume`` over a folder written by another study or with other options (naming the
        options that changed).
    """
    folder = Path(folder)
    ident = json.loads(json_text(dict(identity)))
    path = path or folder / IDENTITY_FILE
    if resume and path.is_file():
        earlier = read_identity(path)
        if earlier != ident:
            why = differences(earlier, ident, option_name or default_option_name)
            raise InputError(
                field,
                f"{folder} holds the runs of another study or of other options ({why}); "
                "run the command as it was run, or without --resume to start again",
            )
    path.parent.mkdir(parents=True, exist_ok=True)  # the runs' folder is made when a run ends
    write_json(path, ident)
    return ident


class Journal:
    """The finished runs of one study in ``folder`` (module docstring).

    Parameters
    ----------
    folder
        Where the records go (made if missing; the caller holds the lock of the output it is
        in).
    identity
        What decides the study's runs (JSON-ready): the command, its options, the scene's hash;
        None: not checked (nothing written).
    resume
        Keep the records of an earlier run of the same study (refused for another study);
        False: clear them (unless ``keep``).
    field
        The option named when a resume is refused.
    identity_file
        Where the identity goes (default ``<folder>/study.json``).
    keep
        The records are the study's result (a batch's ``runs/``): never cleared.
    option_name
        The option a key of the identity stands for (:func:`claim`).

    Raises
    ------
    InputError
        ``resume`` over a journal written by another study or with other options.
    """

    def __init__(
        self,
        folder: str | Path,
        identity: Mapping[str, object] | None,
        resume: bool,
        field: str = "--resume",
        *,
        identity_file: Path | None = None,
        keep: bool = False,
        option_name: Callable[[str], str] | None = None,
    ) -> None:
        self.folder = Path(folder)
        self.identity_file = identity_file or self.folder / IDENTITY_FILE
        self.keep = keep
        self.resumed = 0
        self.damaged: list[str] = []
        if not resume and not keep:
            self.clear()
        self.identity = (
            None
            if identity is None
            else claim(self.folder, identity, resume, field, path=self.identity_file, option_name=option_name)
        )
        if self.folder.is_dir():
            remove_stale_temporaries(self.folder)

    def found(self, name: str, scene_hash: str) -> Found | None:
        """A run finished earlier (:func:`find_run`), counted in ``resumed``; a record that is
        not as it was written goes to ``damaged`` (its run is run again)."""
        found = find_run(self.folder, name, scene_hash)
        if isinstance(found, Found):
            self.resumed += 1
            return found
        if found == DAMAGED:
            self.damaged.append(name)
        return None

    def done(self, name: str, scene_hash: str) -> Cells | None:
        """The row of a run finished earlier (:meth:`found`), or None."""
        found = self.found(name, scene_hash)
        return found.summary if found is not None else None

    def record(self, name: str, record: Record) -> None:
        """Write a finished run's record, durably (:func:`write_run`)."""
        write_run(self.folder, name, record)

    def clear(self) -> None:
        """Remove the journal (its folder and what is in it; never what a link points to)."""
        if self.folder.is_symlink():
            self.folder.unlink()
        elif self.folder.is_dir():
            shutil.rmtree(self.folder)

    def remove_if_empty(self) -> None:
        """Remove the journal if it holds no run (only its identity): nothing to resume."""
        if self.keep or not self.folder.is_dir():
            return
        records = [p for p in self.folder.rglob("*.json") if p.name != IDENTITY_FILE]
        if not records:
            with contextlib.suppress(OSError):
                self.clear()


def default_option_name(key: str) -> str:
    """The option an identity's key stands for: ``options.sample_dt`` is ``--sample-dt``; a key
    outside ``options`` is itself (``scene_hash``)."""
    if key.startswith("options."):
        return "--" + key.removeprefix("options.").replace("_", "-")
    return key


def differences(earlier: object, now: Mapping[str, object], option_name: Callable[[str], str]) -> str:
    """What differs between two identities, in a few words: the options that changed, each
    with its value then and now (never the two whole identities)."""
    if not isinstance(earlier, dict):
        return "its study.json is unreadable"
    if earlier.get("command") != now.get("command"):
        return f"written by '{earlier.get('command')}', not '{now.get('command')}'"
    old, new = _flat(earlier), _flat(now)
    keys = sorted(k for k in {*old, *new} if old.get(k) != new.get(k))
    named: dict[str, str] = {}
    for key in keys:
        name = option_name(key)
        if name not in named:
            named[name] = f"{name}: {_shown(old.get(key))} then, {_shown(new.get(key))} now"
    shown = "; ".join(list(named.values())[:3])
    more = len(named) - 3
    return (shown + (f"; and {more} more" if more > 0 else "")) or "unknown"


def _flat(data: Mapping[str, object], prefix: str = "") -> dict[str, object]:
    out: dict[str, object] = {}
    for key, value in data.items():
        if isinstance(value, Mapping):
            out.update(_flat(value, f"{prefix}{key}."))
        else:
            out[f"{prefix}{key}"] = value
    return out


def _shown(value: object, width: int = 60) -> str:
    text = "missing" if value is None else repr(value)
    return text if len(text) <= width else text[: width - 3] + "..."


__all__ = [
    "DAMAGED",
    "IDENTITY_FILE",
    "KEPT_STATUSES",
    "NOT_FINITE_KEY",
    "SEAL_KEY",
    "Cell",
    "Found",
    "Journal",
    "claim",
    "default_option_name",
    "differences",
    "find_run",
    "marked_record",
    "read_identity",
    "read_run",
    "summary_row",
    "write_run",
]
