"""A worker run's files (its scene data, output and log): where it works, what it keeps, what
it leaves behind. One way for every engine run in a worker (:mod:`rockyade.dem.worker_backend`).

* **Where it works.** In ``workdir`` when one is given (its files are kept after every run),
  else in a private folder ``$TMPDIR/rockyade-<solver>-<pid>-<random>`` (its owner's process
  id in the name). Until the run ends its files carry a working stem, ``<name>.running``, so
  that a run that fails or is interrupted never touches an earlier run's files of that name.
* **What it keeps.** When the run ends its files take their names in the folder that keeps
  them (``workdir``; or ``failed_dir``, after a failed run only): ``<name><tag>.json``,
  ``.npz`` and ``.log``, unless the run failed and that folder holds the output of a
  complete run under the name: then ``<name>_failed<tag>.*`` beside it, so that a failed run
  never replaces the files of a complete one. A successful run that keeps no files removes
  an earlier failed run's ``<name><tag>.*`` from ``failed_dir`` (they were the files of the
  result it replaces). A failed run with neither folder keeps its files in its private
  folder, under their names (the Result's ``log_path`` says where).
* **Interrupted** (Ctrl-C): the run's own files are removed (its private folder whole).
* **Killed** (``kill -9`` of the process, where no clean-up runs): its private folder stays
  until the first run of a later process of that solver, which removes every private folder
  whose owner has died and which holds no kept files (only working files, or nothing).
"""

from __future__ import annotations

import json
import os
import shutil
import stat
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

#: The suffixes of a run's files: its scene data, output and log.
SUFFIXES = (".json", ".npz", ".log")
#: What the working stem adds to the run's name.
WORKING = ".running"

#: The solvers whose stale private folders this process has removed.
_SWEPT: set[str] = set()


@dataclass(frozen=True)
class RunFiles:
    """The files of one run (module docstring).

    Attributes
    ----------
    folder
        Where the run works (absolute).
    name
        The files' stem once the run ended.
    tag
        The engine's part of the file names (".yade", ".siconos").
    private
        ``folder`` is the run's own temporary folder.
    """

    folder: Path
    name: str
    tag: str
    private: bool

    def working(self, suffix: str) -> Path:
        """The run's file ``suffix`` (".json", ".npz", ".log", ".npz.part") while it runs."""
        return self.folder / f"{self.name}{WORKING}{self.tag}{suffix}"

    def discard(self) -> None:
        """Remove the run's own files (an interrupted run)."""
        if self.private:
            shutil.rmtree(self.folder, ignore_errors=True)
            return
        for suffix in (*SUFFIXES, ".npz.part"):
            self.working(suffix).unlink(missing_ok=True)

    def keep(self, ok: bool, workdir: str | Path | None, failed_dir: str | Path | None) -> Path | None:
        """Give the ended run's files their names where they are kept (module docstring).

        Returns
        -------
        Path or None
            Where its log went (None: nothing is kept).
        """
        self.working(".npz.part").unlink(missing_ok=True)  # a worker killed while writing
        into = workdir if workdir is not None else (failed_dir if not ok else None)
        if into is None and ok:
            if failed_dir is not None:  # an earlier failed run's files: those of the result this one replaces
                for suffix in SUFFIXES:
                    (Path(failed_dir) / f"{self.name}{self.tag}{suffix}").unlink(missing_ok=True)
            self.discard()
            return None
        if into is not None:
            try:
                return self._move(Path(into).resolve(), ok)
            except OSError:  # the folder cannot take them: they stay where the run worked
                pass
        return self._move(self.folder, ok)

    def _move(self, into: Path, ok: bool) -> Path:
        into.mkdir(parents=True, exist_ok=True)
        complete = _complete_output(into / f"{self.name}{self.tag}.npz")
        stem = self.name if ok or not complete else f"{self.name}_failed"
        for suffix in SUFFIXES:
            source, target = self.working(suffix), into / f"{stem}{self.tag}{suffix}"
            if source.exists():
                shutil.move(source, target)  # across file systems too (a temporary folder)
            elif suffix != ".log":  # no output of this run: none of an earlier run's stays beside its log
                target.unlink(missing_ok=True)
        if self.private and into != self.folder:
            shutil.rmtree(self.folder, ignore_errors=True)
        return into / f"{stem}{self.tag}.log"


def _complete_output(npz: Path) -> bool:
    """True when ``npz`` is a driver's output of a run that ended complete (not a flush, not
    stopped at its deadline, not failed)."""
    try:
        with np.load(npz, allow_pickle=False) as data:
            meta = json.loads(str(data["meta"]))
    except (OSError, ValueError, KeyError):
        return False
    return isinstance(meta, dict) and meta.get("complete") is True and meta.get("status") != "failed"


def start(solver: str, name: str, tag: str, workdir: str | Path | None) -> RunFiles:
    """The files of a run about to start (module docstring): in ``workdir`` (an earlier killed
    run's working files of that name removed) or in a new private folder (the stale private
    folders of dead processes removed first, once per process)."""
    if workdir is not None:
        folder = Path(workdir).resolve()  # absolute: the worker runs elsewhere
        folder.mkdir(parents=True, exist_ok=True)
        files = RunFiles(folder, name, tag, private=False)
        files.discard()
        return files
    if solver not in _SWEPT:
        _SWEPT.add(solver)
        remove_stale_folders(solver)
    folder = Path(tempfile.mkdtemp(prefix=f"rockyade-{solver}-{os.getpid()}-")).resolve()
    return RunFiles(folder, name, tag, private=True)


def remove_stale_folders(solver: str, where: Path | None = None) -> list[Path]:
    """Remove the private folders of ``solver``'s runs (in ``where``, default the temporary
    folder) left by processes that died during a run: owned by this user, not a link, their
    owner's process gone, and holding only working files (or nothing). Returns them."""
    where = Path(tempfile.gettempdir()) if where is None else where
    removed: list[Path] = []
    try:
        entries = list(where.iterdir())
    except OSError:
        return removed
    prefix = f"rockyade-{solver}-"
    for folder in entries:
        owner = folder.name[len(prefix) :].split("-", 1)[0] if folder.name.startswith(prefix) else ""
        if not owner.isdigit() or _alive(int(owner)):
            continue
        try:
            info = folder.lstat()
            if not stat.S_ISDIR(info.st_mode) or info.st_uid != os.getuid():
                continue
            if all(WORKING in child.name for child in folder.iterdir()):
                shutil.rmtree(folder)
                removed.append(folder)
        except OSError:
            continue
    return removed


def _alive(pid: int) -> bool:
    """True while process ``pid`` exists (another user's included)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return True


__all__ = ["RunFiles", "remove_stale_folders", "start"]
