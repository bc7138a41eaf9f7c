"""Multiple-stripe runs: every record scaled to each intensity level, run through the runner.

Record i, of intensity x_i at load factor 1 (:mod:`rockyade.assess.measures`), is scaled to
the level x of a stripe by the load factor lambda = x / x_i, which multiplies its
accelerations as read (:mod:`rockyade.assess.motions`). The scene's ``[motion]`` is replaced
by the scaled record and its duration by the record's plus a tail of free motion (5 s by
default: a block set rocking late in the record still falls or comes to rest), sampled at
``sample_dt_s`` (0.01 s by default: collapse is the question, not the history).

Each run is a task of :mod:`rockyade.runner` (cost checked before any run, local processes,
Ctrl-C, a failed run never stopping the others); what comes back from a worker is one row,
not the time history. A run **collapses** when

* the scene is a single block: its status is ``overturned`` (the solver's own criterion:
  Housner's |theta| = pi/2, the DEMs' landing on another face);
* the scene has several blocks: at least ``fallen_blocks`` of them fell (default 1), as the
  collapse table of :func:`rockyade.analysis.collapse.collapse_report` says (a block lying
  on another face, carried down by more than half its height, or left leaning beyond its
  tipping angle).

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
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from rockyade.assess.measures import Measure
from rockyade.assess.motions import MotionSet, record_summary
from rockyade.blocks.classical import ClassicalParameters
from rockyade.constants import G
from rockyade.errors import BatchInterruptedError, InputError
from rockyade.result import Result
from rockyade.runner import Executor, Task, check_costs, run_jobs
from rockyade.runner.groups import group_jobs
from rockyade.runner.journal import Journal
from rockyade.runner.tasks import solve
from rockyade.scene import Scene
from rockyade.scene.carried import loaded_classical
from rockyade.solvers.base import GroupSolver, Solver

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
class StripeTask(Task):
    """One run of a stripe: a task (:class:`rockyade.runner.Task`) and what names it.

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
    fallen_blocks
        Fallen blocks that make a collapse (several blocks).
    """

    record_index: int = 0
    record: str = ""
    level_si: float = math.nan
    load_factor: float = math.nan
    fallen_blocks: int = 1
    whole_alpha_rad: float = math.nan


def whole_alpha(scene: Scene) -> float:
    """The whole scene's critical angle, rad: atan of the smaller of its limit-analysis
    multipliers towards +x and -x (for one block its alpha; for a stack turning about its base
    the whole's alpha, b / h_c = tan alpha); NaN without a mechanism."""
    if single_block(scene):
        return float(_classical(scene).alpha_rad)
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


def _classical(scene: Scene) -> ClassicalParameters:
    """The single block's classical parameters as it rocks (the masses of its loads in, each side
    its own alpha: :func:`rockyade.scene.carried.loaded_classical`)."""
    return loaded_classical(scene, G)[scene.blocks[0].name]


def collapse_of(scene: Scene, result: Result, fallen_blocks: int = 1) -> tuple[bool, int, float, float]:
    """(collapsed, blocks fallen, largest peak |theta| / the block's own alpha, largest peak
    |theta| in rad) of a run (module docstring); a single block's rotation on each side over
    that side's alpha (:meth:`rockyade.blocks.classical.ClassicalParameters.theta_over_alpha`)."""
    if single_block(scene):
        spec = scene.blocks[0]
        theta = np.asarray(result.series("theta_rad", spec.name), dtype=float)
        finite = theta[np.isfinite(theta)]
        peak = float(np.max(np.abs(finite))) if finite.size else math.nan
        over = result.status == "overturned"
        return over, int(over), _classical(scene).theta_over_alpha(theta), peak
    from rockyade.analysis.collapse import collapse_report

    report = collapse_report(scene, result)
    fallen = int(report["fell"].sum())
    ratio = float(np.nanmax(report["max_theta_over_alpha"])) if len(report) else math.nan
    peak = float(np.nanmax(report["max_abs_theta_rad"])) if len(report) else math.nan
    return fallen >= fallen_blocks, fallen, ratio, peak


def _row(task: StripeTask, status: str, reason: str) -> dict[str, Any]:
    return {
        "run": task.index,
        "record": task.record,
        "record_index": task.record_index,
        "level_si": task.level_si,
        "load_factor": task.load_factor,
        "solver": task.solver.name,
        "status": status,
        "collapsed": False,
        "n_fallen": 0,
        "max_theta_over_alpha": math.nan,
        "max_theta_over_own_alpha": math.nan,
        "failure_reason": reason,
        "wall_time_s": math.nan,
        "scene_hash": task.scene_hash,
    }


def run_stripe_task(task: StripeTask) -> dict[str, Any]:
    """Run one task and reduce it to its row (what travels back from a worker). Never raises:
    a failed run is a row with status ``failed`` and the reason."""
    start = time.perf_counter()
    result = solve(task)
    row = _row(task, result.status, str(result.meta.failure_reason or ""))
    row["wall_time_s"] = time.perf_counter() - start
    if result.ok:
        try:
            collapsed, fallen, ratio, peak = collapse_of(task.scene, result, task.fallen_blocks)
        except Exception as exc:  # an analysis that fails is this run's failure, not the batch's
            row.update(status="failed", failure_reason=f"collapse analysis: {type(exc).__name__}: {exc}")
        else:
            single = single_block(task.scene) or not math.isfinite(task.whole_alpha_rad)
            whole = ratio if single else peak / task.whole_alpha_rad
            row.update(
                collapsed=bool(collapsed),
                n_fallen=fallen,
                max_theta_over_alpha=whole,
                max_theta_over_own_alpha=ratio,
            )
    return row


def failed_row(task: StripeTask, reason: str) -> dict[str, Any]:
    """The row of a run whose worker gave nothing back (it died)."""
    return _row(task, "failed", reason)


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
                out.append(
                    StripeTask(
                        first_index + len(out),
                        self.solver,
                        self.scene_for(i, lf),
                        {"record": self.motions.label(i), **self.level_labels(level)},
                        record_index=i,
                        record=self.motions.label(i),
                        level_si=float(level),
                        load_factor=lf,
                        fallen_blocks=self.fallen_blocks,
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


def run_name(task: StripeTask) -> str:
    """A run's name in a journal: its scene's hash and its solver."""
    return f"{task.scene_hash}_{task.solver.name}"


def run_stripes(
    plan: StripePlan,
    levels_si: Sequence[float],
    executor: Executor,
    *,
    first_index: int = 0,
    allow_large: bool = False,
    progress: bool = True,
    done_rows: Sequence[dict[str, Any]] = (),
    journal: Journal | None = None,
) -> list[dict[str, Any]]:
    """Run every record at every level; the rows in task order.

    With a ``journal`` (:class:`rockyade.runner.journal.Journal`) a run finished earlier is
    not run again (its row is read back) and each run's row is written there as it ends.

    Raises
    ------
    InputError
        A run above the runner's cost limits (``allow_large`` lifts them), a load factor
        out of range.
    BatchInterruptedError
        Ctrl-C (``done_rows`` and what finished are in its ``rows``).
    """
    tasks = plan.tasks(levels_si, first_index)
    earlier: dict[int, dict[str, Any]] = {}
    if journal is not None:
        for task in tasks:
            row = journal.done(run_name(task), task.scene_hash)
            if row is not None:
                earlier[task.index] = {**row, "run": task.index}
    todo = [t for t in tasks if t.index not in earlier]
    check_costs(todo, allow_large)
    jobs = group_jobs(todo, stripe_group, max(1, min(MAX_RUNS_PER_JOB, -(-len(todo) // (4 * executor.workers)))))

    def on_done(_i: int, job_rows: list[dict[str, Any]]) -> None:
        if journal is not None:
            for row in job_rows:
                task = tasks[row["run"] - first_index]
                journal.record(run_name(task), {"status": row["status"], "scene_hash": task.scene_hash, "summary": row})

    outcome = run_jobs(
        jobs,
        run_stripe_job,
        executor=executor,
        failed=lambda job, reason: [failed_row(task, reason) for task in job],
        on_done=on_done,
        progress=progress,
        desc="runs",
        skipped=len(earlier),
    )
    by_index = {**earlier, **{row["run"]: row for job_rows in outcome.values.values() for row in job_rows}}
    rows = [by_index[k] for k in sorted(by_index)]
    if outcome.unfinished:
        stopped = sum(len(jobs[i]) for i in outcome.unfinished)
        error = BatchInterruptedError(len(done_rows) + len(rows), stopped, None, outcome.hard)
        error.rows = [*done_rows, *rows]  # type: ignore[attr-defined]
        raise error
    return rows


#: Most runs of one group in one job (groups are cut so that every worker gets jobs).
MAX_RUNS_PER_JOB = 64


def stripe_group(task: StripeTask) -> str | None:
    """The group of a run (:func:`rockyade.runner.groups.group_jobs`): runs of one block whose
    solver steps scenes of one structure together (:class:`rockyade.solvers.base.GroupSolver`,
    its ``group_key``: the same block, another record or load factor) go to one job; None: it
    runs alone."""
    solver = task.solver
    if not single_block(task.scene) or not isinstance(solver, GroupSolver):
        return None
    key = solver.group_key(task.scene)
    return None if key is None else f"{solver!r}|{key}"


def run_stripe_job(job: tuple[StripeTask, ...]) -> list[dict[str, Any]]:
    """The rows of a job of :func:`stripe_group`'s group (or of one task). Never raises: should
    the group fail as a whole, its runs are run one by one (:func:`run_stripe_task`).

    A group's runs are the solver's own runs stepped together (the same results, bit for bit,
    as one at a time: :meth:`rockyade.solvers.reference.ReferenceSolver.run_group`); a run
    collapses when its status is ``overturned``, and its peak |theta| is that of its sampled
    rotation, over the block's alpha."""
    if len(job) == 1:
        return [run_stripe_task(job[0])]
    from rockyade.analysis.metrics import uplift_threshold_rad

    start = time.perf_counter()
    solver = job[0].solver
    assert isinstance(solver, GroupSolver)  # stripe_group groups only these
    cp = _classical(job[0].scene)
    alpha = cp.alpha_rad
    try:
        runs = solver.run_group([t.scene for t in job], uplift_threshold_rad(alpha))
    except Exception:  # a run of its own says what went wrong
        return [run_stripe_task(task) for task in job]
    elapsed = (time.perf_counter() - start) / len(job)
    rows = []
    for task, one in zip(job, runs, strict=True):
        row = _row(task, one.status, str(one.meta.failure_reason or ""))
        row["wall_time_s"] = elapsed
        if one.status != "failed":
            over = one.status == "overturned"
            ratio = cp.theta_over_alpha(one.theta_rad)
            row.update(collapsed=over, n_fallen=int(over), max_theta_over_alpha=ratio, max_theta_over_own_alpha=ratio)
        rows.append(row)
    return rows


def runs_frame(rows: Sequence[dict[str, Any]], measure: Measure) -> pd.DataFrame:
    """The runs as a table: :data:`RUN_COLUMNS` and the level in the measure's unit."""
    frame = pd.DataFrame(list(rows), columns=list(RUN_COLUMNS))
    if measure.column != measure.si_column:  # pgv: m/s both ways
        frame.insert(4, measure.column, frame["level_si"] / measure.scale)
    frame = frame.rename(columns={"level_si": measure.si_column})
    return frame.sort_values("run", kind="stable").reset_index(drop=True)
