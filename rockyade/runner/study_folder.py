"""A study's output folder and its whole life, written once for every study: ``batch``,
``fragility``, ``assess``, ``crosscheck``, ``uncertainty`` and the paper's parts.

``--out DIR`` of a study holds its result set (:class:`StudySet`: files replaced as a whole,
the one that marks the set complete written last: :mod:`rockyade.io.resultset`) and the
journal of its finished runs (:class:`rockyade.runner.journal.Journal`): ``DIR/partial/``
while the study is unfinished (``fragility``, ``assess``, ``crosscheck``: the journal goes
when the set is complete and every run answered) or ``DIR/runs/`` for a study whose runs are
its result (``batch``, ``uncertainty``). :class:`StudyFolder`, used as a context manager:

1. refuses, before anything is written (:class:`~rockyade.errors.InputError`, exit 2): an
   ``--out`` that is a symbolic link (dangling or not) or a file, or whose journal folder is a
   link (nothing is written through a link); an ``--out`` that holds another command's result
   set, complete or unfinished, naming that command (one study never writes into another's
   set); ``--resume`` where there is nothing to resume (a complete set and no journal);
2. makes the folder (removed again if the study ends before it wrote anything), locks it
   (:func:`rockyade.io.locking.output_lock`: one writer), settles what a killed study left (a
   swap it committed is finished, temporary files go: :func:`rockyade.io.resultset.settle`);
3. opens the journal under the study's identity (a resume of another study, or of other
   options, is refused naming the options that changed);
4. gives the study :meth:`StudyFolder.replacing` (the new set, swapped in as a whole),
   :meth:`StudyFolder.write_partial` (the partial summary after Ctrl-C, beside the journal) and
   :meth:`StudyFolder.finish` (the set is in: the journal goes, unless a run failed, which
   ``--resume`` then runs again).
"""

from __future__ import annotations

import contextlib
import json
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING

from rockyade.errors import InputError
from rockyade.io.atomic import atomic_open, remove_stale_temporaries, write_json
from rockyade.runner.journal import IDENTITY_FILE, Journal, read_identity

if TYPE_CHECKING:
    import pandas as pd

#: The journal's folder (and the partial summary's) of a study whose runs are not its result.
PARTIAL_DIR = "partial"
#: The runs' folder of a study whose runs are its result (its journal).
RUNS_DIR = "runs"


@dataclass(frozen=True)
class StudySet:
    """The result set of one command.

    Attributes
    ----------
    command
        The command that writes it (``rockyade <command>``).
    names
        Every file a set may have.
    last
        The file that marks a set complete (written last).
    journal
        The journal's folder in ``--out``: :data:`PARTIAL_DIR` (it goes once the set is
        complete) or :data:`RUNS_DIR` (the runs are part of the result, kept).
    what
        The set in words, in messages ("a fragility study").
    """

    command: str
    names: tuple[str, ...]
    last: str
    journal: str = PARTIAL_DIR
    what: str = "a study"

    @property
    def keeps_runs(self) -> bool:
        """The journal is the study's runs, part of its result (never cleared)."""
        return self.journal == RUNS_DIR


#: The result sets of the study commands (a batch's is its summary; an uncertainty study
#: writes a batch summary of its runs beside its report).
BATCH = StudySet("batch", ("summary.parquet", "summary.csv"), "summary.csv", RUNS_DIR, "a batch")
FRAGILITY = StudySet(
    "fragility",
    ("runs.csv", "stripes.csv", "records.csv", "fragility.png", "fragility.json"),
    "fragility.json",
    what="a fragility study",
)
ASSESS = StudySet(
    "assess",
    ("runs.csv", "stripes.csv", "records.csv", "assess.png", "assess.json"),
    "assess.json",
    what="an assessment",
)
CROSSCHECK = StudySet(
    "crosscheck",
    ("collapse_intensities.csv", "pairs.csv", "runs.csv", "crosscheck.json", "crosscheck.png", "index.md"),
    "crosscheck.json",
    what="a cross-check",
)
UNCERTAINTY = StudySet(
    "uncertainty",
    (
        "samples.csv",
        "runs.csv",
        "probabilities.csv",
        "fragility.csv",
        "spread.csv",
        "uncertainty.png",
        "uncertainty.json",
    ),
    "uncertainty.json",
    RUNS_DIR,
    "an uncertainty study",
)
#: Every command's set, the most specific mark first (an uncertainty study's folder also holds
#: a batch summary).
STUDY_SETS = (UNCERTAINTY, CROSSCHECK, FRAGILITY, ASSESS, BATCH)


def check_out(
    out: Path, kind: StudySet, field: str = "--out", resume_field: str | None = None, *, only_its_set: bool = True
) -> None:
    """Refuse, before anything is made or written, an ``out`` that is a link or a file, whose
    journal folder is a link, that holds another command's set (:func:`holders`), or that holds
    files that are not this command's set (:func:`check_only_its_set`): its set would be mixed
    with them.

    Parameters
    ----------
    out, kind
        The folder and the command's set.
    field
        The option that names ``out``.
    resume_field
        The option given to resume (None: not resuming), named when it would resume another
        command's study.
    only_its_set
        Also refuse files that are not the set's (False: the study folder checks them once it
        holds the folder's lock, so that a folder another process is writing in is refused for
        that).

    Raises
    ------
    InputError
        Naming ``field`` and what is wrong (the other command, by name).
    """
    from rockyade.io.folders import refuse_link

    for path in (out, out / kind.journal, out / PARTIAL_DIR):
        refuse_link(path, field)
    if out.exists() and not out.is_dir():
        raise InputError(field, f"{out} is a file; give a folder")
    others = [(command, why) for command, why in holders(out) if command != kind.command]
    if others:
        command, why = others[0]
        resuming = f"; {resume_field} resumes only a study of the same command" if resume_field else ""
        raise InputError(
            field,
            f"{out} holds the results of 'rockyade {command}' ({why}: written by '{command}', not '{kind.command}'"
            f"{resuming}); 'rockyade {kind.command}' never writes over another command's results: give another "
            "folder, or remove that one first",
        )
    if only_its_set:
        check_only_its_set(out, kind, field)


def holders(out: Path) -> list[tuple[str, str]]:
    """The commands whose results (complete sets, or unfinished studies' journals) ``out``
    holds, each once, with the file that says so."""
    found: dict[str, str] = {}
    for path in (out / PARTIAL_DIR / IDENTITY_FILE, out / IDENTITY_FILE):
        identity = read_identity(path)
        command = identity.get("command") if identity is not None else None
        if isinstance(command, str):
            found.setdefault(command, f"{path.relative_to(out)} names it")
    if UNCERTAINTY.command not in found:
        for kind in STUDY_SETS:
            if (out / kind.last).is_file() and not (out / kind.last).is_symlink():
                found.setdefault(kind.command, f"its {kind.last}")
                break  # the most specific mark: an uncertainty study's folder has a batch summary too
    return list(found.items())


def check_only_its_set(out: Path, kind: StudySet, field: str = "--out") -> None:
    """Refuse an ``out`` that holds files that are not ``kind``'s set nor its journal (another
    command's files, a scene, ...): the set would be mixed with them. ``out``, ``kind`` and
    ``field`` as in :func:`check_out`.

    Raises
    ------
    InputError
        Naming ``field`` and the first five files that are not the set's.
    """
    from rockyade.io.folders import refuse_other_files

    summary = BATCH.names if kind.keeps_runs else ()  # a study whose runs are kept has their batch summary
    names = (*kind.names, *summary, kind.journal, PARTIAL_DIR)
    refuse_other_files(out, names, kind.what, f"{kind.command} --out", field)


def check_no_study(out: Path, command: str, field: str = "--out") -> None:
    """Refuse an ``out`` that holds a study's result set or journal (:func:`holders`) for a
    command that writes its own files beside what a folder holds (``compare``): they would be
    mixed with the study's set.

    Raises
    ------
    InputError
        Naming ``field`` and the study's command.
    """
    found = holders(out) if out.is_dir() else []
    if found:
        other, why = found[0]
        raise InputError(
            field,
            f"{out} holds the results of 'rockyade {other}' ({why}); 'rockyade {command}' never writes into "
            "another command's results: give another folder, or remove that one first",
        )


class StudyFolder:
    """A study's output folder while the study runs (module docstring); a context manager.

    Parameters
    ----------
    out
        The folder (made if missing).
    kind
        The command's result set.
    identity
        What decides the study's runs (JSON-ready; its ``command`` is ``kind.command``), or a
        function giving it once the folder's own checks passed; None: not written nor checked
        (a study run from Python without one).
    resume
        Keep the runs an interrupted run of the same study left (refused for another study).
    field
        The option that names ``out`` in errors.
    resume_field
        The option that resumes, in errors (None: the study cannot resume).
    option_name
        The option an identity's key stands for, in a refused resume (default: ``options.tail``
        is ``--tail``).
    say
        Where the folder's notes go (a discarded unfinished study, damaged records).

    Raises
    ------
    InputError
        On entering: :func:`check_out`; ``resume`` with nothing to resume; another process
        writing ``out``; a resume of another study or of other options.
    """

    def __init__(
        self,
        out: str | Path,
        kind: StudySet,
        identity: Mapping[str, object] | Callable[[], Mapping[str, object]] | None,
        resume: bool = False,
        *,
        field: str = "--out",
        resume_field: str | None = "--resume",
        option_name: Callable[[str], str] | None = None,
        say: Callable[[str], None] | None = None,
    ) -> None:
        self.out = Path(out)
        self.kind = kind
        self._identity = identity
        self.resume = resume
        self.field = field
        self.resume_field = resume_field
        self.option_name = option_name
        self.say = say or (lambda _line: None)
        self.created = False
        self._stack: contextlib.ExitStack | None = None
        self._journal: Journal | None = None

    @property
    def journal(self) -> Journal:
        """The journal of finished runs (open while the folder is entered)."""
        if self._journal is None:
            raise RuntimeError("the study folder is not open")
        return self._journal

    @property
    def journal_dir(self) -> Path:
        """The journal's folder."""
        return self.out / self.kind.journal

    @property
    def partial(self) -> Path:
        """Where the partial summary goes after Ctrl-C (beside the journal's records)."""
        return self.out / PARTIAL_DIR

    def complete(self) -> bool:
        """The folder holds a complete set of this command (its last file)."""
        return (self.out / self.kind.last).is_file()

    def unfinished(self) -> bool:
        """An unfinished study of this command left its journal here."""
        return read_identity(self._identity_path()) is not None and not self.kind.keeps_runs

    def _identity_path(self) -> Path:
        return (self.out if self.kind.keeps_runs else self.journal_dir) / IDENTITY_FILE

    def __enter__(self) -> StudyFolder:
        from rockyade.io.folders import output_folder
        from rockyade.io.locking import output_lock

        check_out(self.out, self.kind, self.field, self.resume_field if self.resume else None, only_its_set=False)
        with contextlib.ExitStack() as stack:
            self.created = stack.enter_context(output_folder(self.out))
            stack.enter_context(output_lock(self.out, self.field))
            check_only_its_set(self.out, self.kind, self.field)
            self._settle()
            nothing = not self.kind.keeps_runs and not self.unfinished() and self.complete()
            if self.resume and self.resume_field and nothing:
                raise InputError(
                    self.resume_field,
                    f"{self.out} is a complete '{self.kind.command}' set and nothing is unfinished: there is "
                    f"nothing to resume (run without {self.resume_field} to run the study again)",
                )
            if self.unfinished() and not self.resume:
                self.say(f"discarding the unfinished study in {self.journal_dir} ({self.resume_field} would have "
                         "finished it)")  # fmt: skip
            identity = self._identity() if callable(self._identity) else self._identity
            self._journal = Journal(
                self.journal_dir,
                None if identity is None else {"command": self.kind.command, **identity},
                self.resume,
                self.resume_field or "--resume",
                identity_file=self._identity_path(),
                keep=self.kind.keeps_runs,
                option_name=self.option_name,
            )
            self._stack = stack.pop_all()
        return self

    def __exit__(
        self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> bool | None:
        stack, self._stack = self._stack, None
        try:
            if exc is not None and self._journal is not None:
                self._journal.remove_if_empty()  # an error or Ctrl-C before any run: nothing to resume
        finally:
            if stack is not None:
                stack.__exit__(kind, exc, tb)
        return None

    def _settle(self) -> None:
        """What a killed study left: a committed swap finished, staged sets and temporary files
        removed, half-replaced results of its runs finished or dropped."""
        from rockyade.io.resultset import settle
        from rockyade.result import settle_results

        remove_stale_temporaries(self.out)
        settle(self.out, self.kind.names, self.kind.last)
        if self.kind.keeps_runs:
            settle(self.out, BATCH.names, BATCH.last)
        runs = self.journal_dir
        if runs.is_dir() and not runs.is_symlink():
            settle_results(runs)

    def replacing(self, kind: StudySet | None = None) -> contextlib.AbstractContextManager[Path]:
        """The set (``kind``'s, default the study's) written in a temporary folder and swapped in
        as a whole (:func:`rockyade.io.resultset.replacing_set`)."""
        from rockyade.io.resultset import replacing_set

        kind = kind or self.kind
        return replacing_set(self.out, kind.names, kind.last)

    def write_partial(self, frame: pd.DataFrame, summary: Mapping[str, object]) -> Path:
        """The partial summary after Ctrl-C: ``partial/runs.csv`` (the runs that finished) and
        ``partial/partial.json`` (``"partial": true`` and ``summary``); the CSV's path."""
        self.partial.mkdir(parents=True, exist_ok=True)
        path = self.partial / "runs.csv"
        with atomic_open(path) as fh:
            frame.to_csv(fh, index=False, float_format="%.10g", lineterminator="\n")
        plain = json.loads(json.dumps(dict(summary), default=str))
        write_json(self.partial / "partial.json", {"partial": True, **plain})
        return path

    def finish(self, failed: int = 0) -> None:
        """The set is in: the journal goes, unless ``failed`` runs are in it (``--resume`` runs
        them again, the rest read back) or it is the study's runs."""
        if self.kind.keeps_runs:
            return
        if failed:
            self.say(
                f"{failed} run(s) failed: their records stay in {self.journal_dir}, and the same command with "
                f"{self.resume_field or '--resume'} runs them again (the others are read back)"
            )
            return
        self.journal.clear()

    def writing_token(self) -> str:
        """The token of this folder's lock, for a worker writing in it on the study's behalf
        (:func:`rockyade.io.locking.writing_for`)."""
        from rockyade.io.locking import lock_token

        return lock_token(self.out)


__all__ = [
    "ASSESS",
    "BATCH",
    "CROSSCHECK",
    "FRAGILITY",
    "PARTIAL_DIR",
    "RUNS_DIR",
    "STUDY_SETS",
    "UNCERTAINTY",
    "StudyFolder",
    "StudySet",
    "check_out",
    "holders",
]
