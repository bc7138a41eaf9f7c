"""Multiple-stripe runs: every record scaled to each intensity level, run through the runner.

Record i, of intensity x_i at load factor 1 (:mod:`rockyade.assess.measures`), is scaled to
the level x of a stripe by the load factor lambda = x / x_i, which multiplies its
accelerations as read (:mod:`rockyade.assess.motions`). The scene's ``[motion]`` is replaced
by the scaled record and its duration by the record's plus a tail of free motion (5 s by
default: a block set rocking late in the record still falls or comes to rest), sampled at
``sample_dt_s`` (0.01 s by default: collapse is the question, not the history).

The runs are a study's (:func:`rockyade.batch.study_runs.run_study`: cost checked before any
run, local processes or Dask, Ctrl-C, a failed run never stopping the others, runs of one block
stepped together, each run's record in the study's journal as it ends); what comes back from a
worker is one row, not the time history. A run **collapses** by the one rule of
:func:`rockyade.analysis.collapse_verdict.collapse_verdict`: a single block overturns (its
solver's status), or at least ``fallen_blocks`` blocks of several fall (default 1; the collapse
table's rule: a block lying on another face, carried down by more than half its height, or left
leaning beyond its tipping angle).

A run's row gives its peak rotation as ``max_theta_over_alpha``, the largest |theta| of its
blocks over the whole scene's critical angle (:func:`whole_alpha`: atan of the limit-analysis
multiplier of its mechanism, the whole's alpha for a stack turning about its base), so that a
wall in courses and its monolith, rotating the same, read the same; ``max_theta_over_own_alpha``
keeps the largest of each block's |theta| over its own alpha (a 0.3 m course of a 2.4 m wall
has alpha = 0.876 rad against the wall's 0.124: 7 times smaller a number for the same motion).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import pandas as pd

from rockyade.assess.measures import Measure
from rockyade.assess.motions import MotionSet, record_summary
from rockyade.batch.running import BatchTask, lean_solver, output, run_job, run_task
from rockyade.batch.study_runs import StudyInterruptedError, run_study
from rockyade.constants import G
from rockyade.errors import BatchInterruptedError, InputError
from rockyade.runner import Executor, run_jobs
from rockyade.runner.rows import UNFINISHED, Cells, RunRow
from rockyade.runner.study_folder import PARTIAL_DIR, StudyFolder
from rockyade.scene import Scene
from rockyade.scene.carried import loaded_classical
from rockyade.solvers.base import Solver

if TYPE_CHECKING:
    from rockyade.runner.stopping import StopRequest

#: Free motion after the record, s.
DEFAULT_TAIL_S = 5.0
#: Output sampling of the runs, s.
DEFAULT_SAMPLE_DT_S = 0.01
#: Largest load factor on a record (as a scene's ``load_factor`` allows).
MAX_LOAD_FACTOR = 100.0
#: The columns of a run's row, in order (then the level's column, in the measure's unit).
RUN_COLUMNS = (
    "run",
    "record",
    "record_index",
    "level_si",
    "load_factor",
    "solver",
    "status",
    "collapsed",
    "n_fallen",
    "max_theta_over_alpha",
    "max_theta_over_own_alpha",
    "failure_reason",
    "wall_time_s",
    "scene_hash",
)


def single_block(scene: Scene) -> bool:
    """True when the scene is one block (collapse: its status ``overturned``)."""
    return len(scene.blocks) == 1


def collapse_rule(scene: Scene, fallen_blocks: int) -> str:
    """The rule, in words (module docstring)."""
    if single_block(scene):
        return "the block overturns (the solver's status 'overturned')"
    moving = sum(1 for b in scene.blocks if not b.fixed)
    many = "a block falls" if fallen_blocks == 1 else f"{fallen_blocks} blocks fall"
    return (
        f"{many} (of {moving} moving; rockyade.analysis.collapse: it lies on another face, was carried down, "
        "or is left beyond its tipping angle)"
    )


def check_fallen_blocks(scene: Scene, fallen_blocks: int) -> int:
    """``fallen_blocks`` if it is an integer from 1 to the scene's moving blocks, else InputError."""
    moving = sum(1 for b in scene.blocks if not b.fixed)
    if isinstance(fallen_blocks, bool) or not isinstance(fallen_blocks, int) or not 1 <= fallen_blocks <= moving:
        raise InputError(
            "--fallen-blocks", f"must be an integer in [1, {moving}] (the moving blocks), got {fallen_blocks!r}"
        )
    if single_block(scene) and fallen_blocks != 1:
        raise InputError("--fallen-blocks", "applies to scenes of several blocks")
    return fallen_blocks


@dataclass(frozen=True)
class StripeTask(BatchTask):
    """One run of a stripe: a study's task (:class:`rockyade.batch.running.BatchTask`: no
    history, no metrics, the collapse verdict) and what names it.

    Attributes
    ----------
    record_index
        The record's 0-based index in its set.
    record
        The record's label.
    level_si
        The stripe's intensity, SI (m/s^2 or m/s).
    load_factor
        lambda on the record's accelerations.
    whole_alpha_rad
        The whole scene's critical angle (:func:`whole_alpha`), rad.
    """

    record_index: int = 0
    record: str = ""
    level_si: float = math.nan
    load_factor: float = math.nan
    whole_alpha_rad: float = math.nan


def whole_alpha(scene: Scene) -> float:
    """The whole scene's critical angle, rad: atan of the smaller of its limit-analysis
    multipliers towards +x and -x (for one block its alpha; for a stack turning about its base
    the whole's alpha, b / h_c = tan alpha); NaN without a mechanism."""
    if single_block(scene):
        return float(loaded_classical(scene, G)[scene.blocks[0].name].alpha_rad)  # the body that rocks
    from rockyade.limit import limit_analysis

    lams = []
    for direction in ("+x", "-x"):
        try:
            lam = limit_analysis(scene, direction, nonlinear=False).load_multiplier
        except InputError:
            lam = None
        if lam is not None and math.isfinite(lam):
            lams.append(lam)
    return math.atan(min(lams)) if lams else math.nan


def stripe_row(task: StripeTask, row: RunRow) -> Cells:
    """A run's row in the stripes' table (:data:`RUN_COLUMNS`): its verdict, its peak rotation
    over the whole scene's alpha and over each block's own (module docstring)."""
    verdict = row.verdict if row.answered else None
    own = verdict.peak_over_own_alpha if verdict is not None else math.nan
    whole = own  # a single block: each side's rotation over that side's alpha
    if verdict is not None and not single_block(task.scene) and math.isfinite(task.whole_alpha_rad):
        whole = verdict.peak_theta_rad / task.whole_alpha_rad
    return {
        "run": task.index,
        "record": task.record,
        "record_index": task.record_index,
        "level_si": task.level_si,
        "load_factor": task.load_factor,
        "solver": row.solver,
        "status": row.status,
        "collapsed": bool(row.collapsed),
        "n_fallen": verdict.n_fallen if verdict is not None else 0,
        "max_theta_over_alpha": whole,
        "max_theta_over_own_alpha": own,
        "failure_reason": row.failure_reason,
        "wall_time_s": row.elapsed_s if row.elapsed_s is not None else math.nan,
        "scene_hash": row.scene_hash,
    }


def run_stripe_task(task: StripeTask) -> Cells:
    """Run one task alone (:func:`rockyade.batch.running.run_task`) and give its stripe row.
    Never raises: a failed run is a row with status ``failed`` and the reason."""
    return stripe_row(task, run_task(task))


def run_stripe_job(job: tuple[StripeTask, ...]) -> list[Cells]:
    """The stripe rows of a job of runs that share a structure
    (:func:`rockyade.batch.running.run_job`: the solver steps them together, the rows of the
    runs one at a time)."""
    return [stripe_row(task, row) for task, row in zip(job, run_job(job), strict=True)]


class StripesInterruptedError(BatchInterruptedError):
    """Ctrl-C stopped the stripes: ``rows``, the stripe rows of the runs that finished (those
    of earlier rounds first), for the partial summary; ``plan``, the fragility plan when known."""

    def __init__(self, rows: list[Cells], unfinished: int, hard: bool) -> None:
        super().__init__(len(rows), unfinished, None, hard)
        self.rows = rows
        self.plan: object | None = None


@dataclass(frozen=True)
class StripePlan:
    """What every run of a multiple-stripe analysis shares.

    Attributes
    ----------
    scene
        The scene whose motion is replaced.
    motions
        The records.
    measure
        The intensity measure of the levels.
    im_si
        Each record's intensity at load factor 1, SI.
    durations_s
        Each record's duration, s.
    solver
        The solver (with its options).
    fallen_blocks
        Fallen blocks that make a collapse (several blocks).
    sample_dt_s, tail_s
        Output sampling and free motion after the record, s.
    """

    scene: Scene
    motions: MotionSet
    measure: Measure
    im_si: tuple[float, ...]
    durations_s: tuple[float, ...]
    solver: Solver
    fallen_blocks: int = 1
    sample_dt_s: float = DEFAULT_SAMPLE_DT_S
    tail_s: float = DEFAULT_TAIL_S

    @functools.cached_property
    def whole_alpha_rad(self) -> float:
        """The whole scene's critical angle (:func:`whole_alpha`), rad: a run's
        ``max_theta_over_alpha`` is its peak rotation over it (``max_theta_over_own_alpha``
        keeps each block's own)."""
        return whole_alpha(self.scene)

    def scene_for(self, i: int, load_factor: float) -> Scene:
        """The scene of record i at ``load_factor`` (module docstring)."""
        motion = self.motions.motion(i, load_factor)
        return dataclasses.replace(
            self.scene, motion=motion, duration_s=self.durations_s[i] + self.tail_s, sample_dt_s=self.sample_dt_s
        )

    def load_factor(self, i: int, level_si: float) -> float:
        """lambda that brings record i to ``level_si``; InputError above :data:`MAX_LOAD_FACTOR`."""
        lf = level_si / self.im_si[i]
        if not (math.isfinite(lf) and 0.0 < lf <= MAX_LOAD_FACTOR):
            shown = self.measure.shown(level_si)
            raise InputError(
                "--levels",
                f"{self.motions.label(i)} would need a load factor of {lf:.4g} to reach {self.measure.name} = "
                f"{shown:.4g} {self.measure.unit} (its own is {self.measure.shown(self.im_si[i]):.4g}); at most "
                f"{MAX_LOAD_FACTOR:g} is allowed: lower the levels or leave that record out",
            )
        return lf

    def level_labels(self, level: float) -> dict[str, float]:
        """What names a level in a task's labels: the measure in its shown unit."""
        return {self.measure.column: self.measure.shown(level)}

    def tasks(self, levels_si: Sequence[float], first_index: int = 0) -> list[StripeTask]:
        """One task per record and level (level by level)."""
        out: list[StripeTask] = []
        for level in levels_si:
            for i in range(self.motions.count):
                lf = self.load_factor(i, level)
                scene = self.scene_for(i, lf)
                out.append(
                    StripeTask(
                        first_index + len(out),
                        lean_solver(self.solver, scene),
                        scene,
                        {"record": self.motions.label(i), **self.level_labels(level)},
                        save_history=False,
                        metrics=False,
                        fallen_blocks=self.fallen_blocks,
                        record_index=i,
                        record=self.motions.label(i),
                        level_si=float(level),
                        load_factor=lf,
                        whole_alpha_rad=self.whole_alpha_rad,
                    )
                )
        return out


@dataclass(frozen=True)
class LoadFactorStripes(StripePlan):
    """Stripes whose levels are load factors: every record scaled by the same lambda (a suite
    scaled as a whole, the paper's way; its intensity is then a nominal one, e.g. lambda x ag S,
    not each record's own). ``levels_si`` given to :meth:`tasks` and :func:`run_stripes` are
    the load factors themselves (a task's ``level_si`` too), so that each run's load factor is
    exactly the one asked for; ``measure`` and ``im_si`` are what lambda = 1 stands for."""

    def load_factor(self, i: int, level_si: float) -> float:
        """The level itself; InputError outside (0, :data:`MAX_LOAD_FACTOR`]."""
        if not (math.isfinite(level_si) and 0.0 < level_si <= MAX_LOAD_FACTOR):
            raise InputError("load_factor", f"must be in (0, {MAX_LOAD_FACTOR:g}], got {level_si!r}")
        return float(level_si)

    def level_labels(self, level: float) -> dict[str, float]:
        """The load factor."""
        return {"load_factor": float(level)}


def record_measures(
    motions: MotionSet, measure: Measure | None, executor: Executor, progress: bool = True
) -> pd.DataFrame:
    """Per record: ``duration_s``, ``pga_m_s2`` and the measure ``im_si`` at load factor 1
    (a synthetic suite's records are generated, or read from the cache, on ``executor``)."""
    jobs = [(motions, i, measure) for i in range(motions.count)]
    outcome = run_jobs(jobs, record_summary, executor=executor, progress=progress, desc="records")
    if outcome.unfinished:
        raise KeyboardInterrupt
    return pd.DataFrame(outcome.in_order())


def run_stripes(
    plan: StripePlan,
    levels_si: Sequence[float],
    executor: Executor,
    *,
    first_index: int = 0,
    allow_large: bool = False,
    progress: bool = True,
    done_rows: Sequence[Cells] = (),
    folder: StudyFolder | None = None,
    stop: StopRequest | None = None,
) -> list[Cells]:
    """Run every record at every level (:func:`rockyade.batch.study_runs.run_study`); the
    stripe rows in task order.

    With a ``folder`` (:class:`rockyade.runner.study_folder.StudyFolder`) each run's record is
    written in its journal as the run ends, and a run finished earlier is read back rather than
    run again.

    Raises
    ------
    InputError
        A run above the runner's cost limits (``allow_large`` lifts them), a load factor
        out of range.
    StripesInterruptedError
        Ctrl-C (``done_rows`` and what finished are in its ``rows``).
    """
    tasks = plan.tasks(levels_si, first_index)
    files = None
    if folder is not None:  # the records go in the journal: rows and verdicts, no solver's files
        files = output(folder.out, folder.writing_token(), PARTIAL_DIR, lean=True)
    try:
        runs = run_study(
            tasks,
            executor=executor,
            journal=folder.journal if folder is not None else None,
            files=files,
            allow_large=allow_large,
            progress=progress,
            stop=stop,
            tell_failures=False,
        )
    except StudyInterruptedError as exc:
        finished = [stripe_row(t, r) for t, r in zip(tasks, exc.runs.rows, strict=True) if r.status != UNFINISHED]
        raise StripesInterruptedError([*done_rows, *finished], exc.runs.unfinished, exc.runs.hard) from None
    return [stripe_row(task, row) for task, row in zip(tasks, runs.rows, strict=True)]


def runs_frame(rows: Sequence[Cells], measure: Measure) -> pd.DataFrame:
    """The runs as a table: :data:`RUN_COLUMNS` and the level in the measure's unit."""
    frame = pd.DataFrame(list(rows), columns=list(RUN_COLUMNS))
    if measure.column != measure.si_column:  # pgv: m/s both ways
        frame.insert(4, measure.column, frame["level_si"] / measure.scale)
    frame = frame.rename(columns={"level_si": measure.si_column})
    return frame.sort_values("run", kind="stable").reset_index(drop=True)
