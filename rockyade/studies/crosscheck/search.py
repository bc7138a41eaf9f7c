"""A cross-check run (:mod:`rockyade.studies.crosscheck`): its collapse searches advanced
together, one round at a time, in its output folder.

For each solver, each time-step factor and each record, a collapse search: the scan's levels,
then bisection to the resolution (:func:`rockyade.analysis.crosscheck_statistics.next_levels`).
Each round's runs are a study's runs (:func:`rockyade.batch.study_runs.run_study`: the runner's
executors, grouped runs, each run's record written as it ends, its collapse verdict by the one
rule of :func:`rockyade.analysis.collapse_verdict.collapse_verdict`).

Files. ``--out`` is the study's folder (:class:`rockyade.runner.study_folder.StudyFolder`): the
complete set (``collapse_intensities.csv``, ``pairs.csv``, ``runs.csv``, ``crosscheck.png``,
``index.md`` and ``crosscheck.json``, the file that marks it complete) and, while the study is
unfinished, its journal ``<out>/partial/``: ``study.json`` (what the study is), ``dt<f>/runs/``
(one JSON per finished run, by scene hash and solver, one folder per time-step factor) and,
after Ctrl-C, a summary marked PARTIAL. When every search is done the summary is written as a
new set that replaces the old one as a whole (:mod:`rockyade.io.resultset`): an error, Ctrl-C
or a kill leaves the previous complete set, or the new one, never a mix; then the journal goes
(it stays when a run failed: ``--resume`` runs the failed runs again and goes on with their
searches).

Ctrl-C. One stop request spans every round: after a Ctrl-C no new run starts, in this round or
a later one; the study stops with the partial summary (``partial/index.md``) and exit 130,
whether the Ctrl-C came during a round, at its end or while the final set was written.

Resume. Every search is a function of its outcomes, so ``--resume`` replays the searches
from the journal's runs and runs only what is missing (a run that failed is run again); after
Ctrl-C or kill -9 no finished run is repeated. Without ``--resume`` an unfinished study's
journal is discarded and the study starts afresh; with it, a study whose identity differs is
refused, naming the options that changed.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from rockyade.batch import BatchTask, batch_task, run_study
from rockyade.batch.running import output
from rockyade.errors import BatchInterruptedError
from rockyade.runner import Executor
from rockyade.runner.journal import Journal
from rockyade.runner.rows import Cell, RunRow
from rockyade.runner.stopping import StopRequest
from rockyade.runner.study_folder import CROSSCHECK, PARTIAL_DIR, StudyFolder
from rockyade.runner.study_folder import check_out as check_study_out
from rockyade.solvers import solver_class
from rockyade.solvers.base import GroupSolver
from rockyade.studies.crosscheck.plan import CrosscheckPlan, Outcomes, option_name
from rockyade.studies.crosscheck.reporting import Summary, summarise, write_summary

#: A run of a search: (solver, dt factor, record index), its level (SI) and its task.
Pending = tuple[tuple[str, float, int], float, BatchTask]


def journal_dir(out: Path) -> Path:
    """The journal of an unfinished cross-check writing ``out`` (its runs, its identity and,
    after Ctrl-C, the partial summary)."""
    return Path(out) / PARTIAL_DIR


def check_out(out: Path, resume: bool = False) -> None:
    """Refuse, before the plan is made, an ``--out`` the study folder would refuse
    (:func:`rockyade.runner.study_folder.check_out`: a link, a file, another command's results)."""
    check_study_out(Path(out), CROSSCHECK, resume_field="--resume" if resume else None)


class Study:
    """A cross-check being run in its working folder (module docstring).

    Parameters
    ----------
    plan
        What it runs.
    stage
        Its journal's folder (``<out>/partial``).
    executor
        Where its runs run.
    progress, allow_large, say
        Progress bars, the cost limits lifted, where its lines go.
    out, token
        The locked output folder and its lock's token (the runs write their records there on
        the study's behalf; default: the folder above ``stage``, no token).
    stop
        The stop request spanning the rounds (default: a fresh one, never set).
    """

    def __init__(
        self,
        plan: CrosscheckPlan,
        stage: Path,
        executor: Executor,
        *,
        progress: bool,
        allow_large: bool,
        say: Callable[[str], None],
        out: Path | None = None,
        token: str = "",
        stop: StopRequest | None = None,
    ) -> None:
        self.plan = plan
        self.stage = stage
        self.executor = executor
        self.progress = progress
        self.allow_large = allow_large
        self.say = say
        self.out = out or stage.parent
        self.token = token
        self.stop = stop or StopRequest()
        self.outcomes = Outcomes()
        self.ran = 0
        self.reused = 0
        self.solvers = {(s, f): plan.solver(s, f) for s in plan.solvers for f in plan.dt_factors}
        self.journals = {f: Journal(self.folder(f) / "runs", None, True, keep=True) for f in plan.dt_factors}

    def folder(self, dt_factor: float) -> Path:
        """Where the runs at ``dt_factor`` go."""
        return self.stage / f"dt{dt_factor:g}"

    def task(self, key: tuple[str, float, int], level: float) -> BatchTask:
        """The task of one run: no history, no metrics, the collapse verdict."""
        solver, f, i = key
        sp = self.plan.stripes.stripes
        lf = sp.load_factor(i, level)
        m = self.plan.measure
        labels: dict[str, Cell] = {
            "record": sp.motions.label(i),
            "record_index": i,
            "dt_factor": f,
            "level_si": level,
            m.column: m.shown(level),
            "load_factor": lf,
        }
        scene = sp.scene_for(i, lf)
        return batch_task(
            0,
            self.solvers[(solver, f)],
            scene,
            labels,
            save_history=False,
            metrics=False,
            fallen_blocks=sp.fallen_blocks,
        )

    def pending(self) -> list[Pending]:
        """The runs of the next round: each search advanced over the runs on disk first."""
        plan = self.plan
        todo: list[Pending] = []
        for key in plan.searches():
            i = key[2]
            verdicts = self.outcomes.verdicts.setdefault(key, {})
            while True:
                # a level already run that failed: the search ends
                levels = [level for level in plan.next_levels(i, verdicts) if level not in verdicts]
                missing = []
                for level in levels:
                    task = self.task(key, level)
                    found = self.journals[key[1]].found(task.name, task.scene_hash)
                    if found is None:
                        missing.append((key, level, task))
                    else:
                        self.reused += 1
                        self.outcomes.add_run(key, level, RunRow.from_record(task, found.summary, found.verdict))
                if missing or not levels:
                    todo += missing
                    break
        return todo

    def warm_up(self) -> None:
        """Load (or, on a cold numba cache, compile) in this process the compiled code of the
        solvers that run in process, as the rounds run them (the lean solver of
        :func:`rockyade.batch.batch_task`: without energy terms), on a run of 0.05 s: both the
        grouped path (a :class:`rockyade.solvers.base.GroupSolver`'s ``run_group``) and the run
        of its own. The worker processes forked for each round inherit it: every worker of every
        round would load the kernels again and, on a cold cache, compile the same kernels at
        once (minutes of CPU under load; docs/verification.md, "Cost")."""
        from rockyade.analysis.metrics import uplift_threshold_rad

        if self.executor.in_process or not self.plan.scene.blocks:
            return
        level = self.plan.scan_si[0]
        for name, f in self.solvers:
            if not solver_class(name).IN_PROCESS:
                continue
            task = self.task((name, f, 0), level)
            scene = replace(task.scene, duration_s=min(task.scene.duration_s, 0.05))
            lean = task.solver
            try:
                if isinstance(lean, GroupSolver) and lean.group_key(scene) is not None:
                    lean.run_group([scene], uplift_threshold_rad(scene.blocks[0].classical().alpha_rad))
                lean.run(scene)
            except Exception:  # a warm-up that fails costs only time; the runs say what is wrong
                continue

    def run(self) -> None:
        """Run rounds until every search is done.

        Raises
        ------
        BatchInterruptedError
            Ctrl-C, in a round or between two (what finished is on disk).
        """
        rounds = 0
        self.warm_up()
        while True:
            todo = self.pending()
            if self.stop.requested:  # a Ctrl-C at the end of the last round: no new round starts
                raise BatchInterruptedError(0, len(todo), None, self.stop.now)
            if not todo:
                return
            rounds += 1
            self.say(f"round {rounds}: {len(todo)} run(s)")
            for f in self.plan.dt_factors:
                part = [(key, level, task) for key, level, task in todo if key[1] == f]
                if not part:
                    continue
                tasks = [replace(task, index=n) for n, (_k, _l, task) in enumerate(part)]
                runs = run_study(
                    tasks,
                    executor=self.executor,
                    journal=self.journals[f],
                    files=output(self.out, self.token, str(self.folder(f).relative_to(self.out) / "runs")),
                    allow_large=self.allow_large,
                    progress=self.progress,
                    desc=f"crosscheck dt x {f:g}, round {rounds}",
                    stop=self.stop,
                )
                for (key, level, _task), row in zip(part, runs.rows, strict=True):
                    self.ran += 1
                    self.outcomes.add_run(key, level, row)

    def failed(self) -> int:
        """Runs that failed (no verdict): ``--resume`` runs them again."""
        return sum(v is None for verdicts in self.outcomes.verdicts.values() for v in verdicts.values())


def run_crosscheck(
    plan: CrosscheckPlan,
    out: str | Path,
    executor: Executor,
    *,
    resume: bool = False,
    progress: bool = True,
    allow_large: bool = False,
    say: Callable[[str], None] = print,
) -> Summary:
    """Run the study in ``out``'s journal and replace ``out``'s set with the complete one
    (module docstring).

    Raises
    ------
    InputError
        ``out`` a link or a file or another command's, a resume of another study or of nothing,
        a run above the cost limits, another process writing ``out``.
    BatchInterruptedError
        Ctrl-C: the partial summary is in ``<out>/partial``; ``--resume`` finishes it.
    """
    start = time.perf_counter()
    with StudyFolder(out, CROSSCHECK, lambda: plan.identity(), resume, say=say, option_name=option_name) as folder:
        stage = folder.partial
        with StopRequest(raise_on_second=executor.in_process) as stop:
            study = Study(
                plan,
                stage,
                executor,
                progress=progress,
                allow_large=allow_large,
                say=say,
                out=folder.out,
                token=folder.writing_token(),
                stop=stop,
            )
            try:
                study.run()
            except BatchInterruptedError as exc:
                _interrupted(study, stage, time.perf_counter() - start, exc.unfinished, exc.hard)
        try:
            summary = summarise(plan, study.outcomes, partial=False)
            with folder.replacing() as target:
                extra = {"runs_made": study.ran, "runs_reused": study.reused}
                write_summary(plan, summary, target, time.perf_counter() - start, extra)
        except KeyboardInterrupt:  # Ctrl-C during the final write: the previous set stays, the journal too
            _interrupted(study, stage, time.perf_counter() - start, 0, False)
        folder.finish(study.failed())
        say(f"{study.ran} run(s) made, {study.reused} found done")
    return summary


def _interrupted(study: Study, stage: Path, seconds: float, unfinished: int, hard: bool) -> None:
    """After Ctrl-C: the partial summary of what finished in ``stage`` (``index.md`` marked
    PARTIAL, ``runs.csv``), then the interruption for the command to end with.

    Raises
    ------
    BatchInterruptedError
        Always: naming the partial ``runs.csv`` and ``--resume``.
    """
    study.pending()  # what the interrupted round finished, read back from disk
    summary = summarise(study.plan, study.outcomes, partial=True)
    write_summary(study.plan, summary, stage, seconds, {"runs_made": study.ran})
    study.say(f"partial summary in {stage / 'index.md'}")
    raise BatchInterruptedError(
        len(summary.runs),
        unfinished,
        str(stage / "runs.csv"),
        hard,
        "--resume",
        listed="the finished runs (the searches' later runs are chosen from them when resumed)",
        unfinished_what="of the interrupted round unfinished",
    ) from None


__all__ = ["Study", "check_out", "journal_dir", "run_crosscheck"]
