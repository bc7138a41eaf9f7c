"""What every command that runs many runs shares: ``--executor``/``--scheduler`` (as
``batch`` takes them), ``--resume``, the journal of finished runs in ``--out``, the partial
summary after Ctrl-C, and the result set replaced as a whole.

``--out DIR`` of such a command holds its result set (replaced as a whole:
:mod:`rockyade.io.resultset`) and, while a study is unfinished, ``DIR/partial/``: the
journal (:class:`rockyade.runner.journal.Journal`, one durable record per finished run and
``study.json``) and, after Ctrl-C, the partial summary (``runs.csv`` and ``partial.json``,
marked ``"partial": true``). ``--resume`` reads the journal back; a complete set removes it.
"""

from __future__ import annotations

import argparse
import contextlib
import hashlib
import json
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rockyade.errors import InputError

if TYPE_CHECKING:
    from rockyade.runner import Executor
    from rockyade.runner.journal import Journal

#: The journal and partial summary's folder in ``--out``.
PARTIAL_DIR = "partial"


def add_executor_options(p: argparse.ArgumentParser) -> None:
    """``--workers``, ``--executor``, ``--scheduler``, ``--scheduler-timeout`` and ``--resume``,
    as ``batch`` takes them."""
    p.add_argument("--workers", type=int, default=2, help="parallel workers (default 2)")
    p.add_argument(
        "--executor",
        choices=["local", "dask"],
        default="local",
        help="local processes (default) or Dask (its threaded scheduler here, or --scheduler's cluster)",
    )
    p.add_argument(
        "--scheduler",
        help="Dask scheduler address, e.g. tls://host:8786 (default: Dask's threaded scheduler in this "
        "process; no port opens). See docs/batches.md",
    )
    p.add_argument(
        "--scheduler-timeout", type=float, default=10.0, help="seconds to wait for the scheduler (default 10)"
    )
    p.add_argument(
        "--resume",
        action="store_true",
        help="keep the runs an interrupted run of the same command left in --out (partial/) and run only the others",
    )


def executor_from(args: argparse.Namespace) -> Executor:
    """The executor of ``--executor``, ``--workers``, ``--scheduler``, ``--scheduler-timeout``
    (checked before any work; InputError naming the option)."""
    from rockyade.runner import Executor

    try:
        return Executor(args.executor, args.workers, args.scheduler, args.scheduler_timeout)
    except InputError as exc:
        flag = {"workers": "--workers", "scheduler": "--scheduler", "scheduler_timeout_s": "--scheduler-timeout"}
        raise InputError(flag.get(exc.field, "--executor"), exc.message) from None


def identity(command: str, args: argparse.Namespace, scene_hash: str, ignore: Sequence[str] = ()) -> dict[str, Any]:
    """What decides a command's runs: its name, the scene's hash and every option but those
    that only say where or how it runs (``--out``, ``--resume``, the executor, progress)."""
    skip = {
        "out",
        "resume",
        "quiet",
        "json",
        "workers",
        "executor",
        "scheduler",
        "scheduler_timeout",
        "func",
        "started_at",
        "command",
        *ignore,
    }
    options = {k: _plain(v) for k, v in sorted(vars(args).items()) if k not in skip}
    return {"command": command, "scene_hash": scene_hash, "options": options}


def _plain(value: Any) -> Any:
    if isinstance(value, Path):
        return str(value)
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    return repr(value)


def file_digest(path: Path) -> str:
    """SHA-256 of a file's bytes (a scene's identity as given)."""
    return hashlib.sha256(path.read_bytes()).hexdigest()[:16]


@dataclass
class StudyOutput:
    """An output folder of a study while it runs (module docstring)."""

    out: Path
    journal: Journal
    created: bool

    @property
    def partial(self) -> Path:
        """The journal's folder."""
        return self.journal.folder


@contextlib.contextmanager
def study_output(
    out: Path, ident: Mapping[str, Any], resume: bool, names: Sequence[str], last: str
) -> Iterator[StudyOutput]:
    """Make ``out`` (after every check: the caller validated its input), lock it, settle what
    a killed run left, open its journal. On an error or Ctrl-C that leaves no finished run, a
    folder made here is removed again (no empty ``--out``).

    Raises
    ------
    InputError
        Another process writes ``out``; ``resume`` over another study's journal.
    """
    from rockyade.io.folders import output_folder
    from rockyade.io.locking import output_lock
    from rockyade.io.resultset import settle
    from rockyade.runner.journal import Journal

    with output_folder(out) as created, output_lock(out, "--out"):
        settle(out, names, last)
        journal = Journal(out / PARTIAL_DIR, ident, resume)
        ok = False
        try:
            yield StudyOutput(out, journal, created)
            ok = True
        finally:
            if not ok:
                journal.remove_if_empty()


def write_partial(output: StudyOutput, frame: Any, summary: Mapping[str, Any]) -> Path:
    """The partial summary after Ctrl-C: ``partial/runs.csv`` (what finished) and
    ``partial/partial.json`` (``"partial": true`` and ``summary``); the CSV's path."""
    from rockyade.io.atomic import atomic_open, write_json

    path = output.partial / "runs.csv"
    with atomic_open(path) as fh:
        frame.to_csv(fh, index=False, float_format="%.10g", lineterminator="\n")
    write_json(output.partial / "partial.json", {"partial": True, **json.loads(json.dumps(dict(summary), default=str))})
    return path


def finish(output: StudyOutput) -> None:
    """The set is complete: the journal goes."""
    output.journal.clear()


__all__ = [
    "PARTIAL_DIR",
    "StudyOutput",
    "add_executor_options",
    "executor_from",
    "file_digest",
    "finish",
    "identity",
    "study_output",
    "write_partial",
]
