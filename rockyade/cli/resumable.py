"""What every command that runs many runs shares on the command line: ``--executor``,
``--scheduler`` and ``--workers`` (as ``batch`` takes them), ``--resume``, and the study's
identity (what decides its runs). The output folder's life (lock, journal, partial summary, the
set replaced as a whole) is :class:`rockyade.runner.study_folder.StudyFolder`'s.
"""

from __future__ import annotations

import argparse
import hashlib
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from rockyade.errors import InputError

if TYPE_CHECKING:
    from rockyade.runner import Executor
    from rockyade.runner.tasks import Cell


def add_executor_options(p: argparse.ArgumentParser, resume_help: str | None = None) -> None:
    """``--workers``, ``--executor``, ``--scheduler``, ``--scheduler-timeout`` and ``--resume``
    (``resume_help``: what it does for this command), the same for every study command."""
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
        help=resume_help
        or "keep the runs an interrupted run of the same command left in --out (partial/) and run only the others",
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


def identity(command: str, args: argparse.Namespace, scene_hash: str, ignore: Sequence[str] = ()) -> dict[str, object]:
    """What decides a command's runs: its name, the scene's hash and every option but those
    that only say where or how it runs (``--out``, ``--resume``, the executor, progress). A
    path is the file or folder it names (resolved): the same records given by a relative or an
    absolute path are the same study."""
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


def _plain(value: object) -> Cell:
    if isinstance(value, Path):
        return str(value.resolve())
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    return repr(value)


def file_digest(path: Path) -> str:
    """SHA-256 of a file's bytes (a scene's identity as given)."""
    return hashlib.sha256(path.read_bytes()).hexdigest()[:16]


__all__ = ["add_executor_options", "executor_from", "file_digest", "identity"]
