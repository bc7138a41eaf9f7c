"""A run's row: the one typed record of a finished (or unfinished) run that every study keeps.

Every study (``batch``, ``fragility``, ``assess``, ``crosscheck``, ``uncertainty``, the paper's
parts) turns each of its runs into a :class:`RunRow`: what names the run (its position, its
name ``<scene hash>_<solver>``, the task's labels), how it ended (status, reason, overturn,
wall time), how much of the base motion it left out, the collapse :class:`Verdict` (when the
study asks for one: :func:`rockyade.analysis.collapse.collapse_verdict`) and its metrics (when
the study asks for them: :func:`rockyade.analysis.metrics.summary_metrics`).

A row goes to disk as the ``summary`` (a flat mapping: :meth:`RunRow.summary`) and the
``verdict`` of its record in the study's journal (:mod:`rockyade.runner.journal`), and comes
back from there with :meth:`RunRow.from_record`; a study's tables are made of rows.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace

from rockyade.result import Result
from rockyade.run_meta import RunMeta
from rockyade.runner.tasks import Cell, Task

#: A row as a flat mapping (a table's row, a record's ``summary``).
Cells = dict[str, Cell]

#: Status of a run that a Ctrl-C stopped or kept from starting (a study's table only).
UNFINISHED = "unfinished"
#: Statuses of a run that ended with an answer (a failed run has none).
ANSWERED = ("completed", "overturned")
#: The leading columns of a row, then its labels, then :data:`STATUS_COLUMNS`.
LEADING_COLUMNS = ("index", "run", "scene_hash", "solver")
STATUS_COLUMNS = (
    "status",
    "duplicate_of",
    "failure_reason",
    "overturn_time_s",
    "overturned_block",
    "wall_time_s",
    "elapsed_s",
    "motion_time_left_out_s",
    "motion_pga_left_out_fraction",
)
#: The columns of how much of the base motion a run leaves out (:func:`coverage_columns`).
COVERAGE_COLUMNS = ("motion_time_left_out_s", "motion_pga_left_out_fraction")


@dataclass(frozen=True)
class Verdict:
    """Whether a run collapsed, by the one rule of :func:`rockyade.analysis.collapse.collapse_verdict`.

    Attributes
    ----------
    collapsed
        At least the study's number of blocks fell.
    fallen
        The blocks that fell, by name.
    peak_theta_rad
        The largest peak |theta| of the run's blocks, rad (NaN: none finite).
    peak_over_own_alpha
        The largest of each block's peak |theta| over its own alpha.
    """

    collapsed: bool
    fallen: tuple[str, ...]
    peak_theta_rad: float
    peak_over_own_alpha: float

    @property
    def n_fallen(self) -> int:
        """How many blocks fell."""
        return len(self.fallen)

    def to_dict(self) -> Cells:
        """JSON-ready (the ``verdict`` of a run's record)."""
        return {
            "collapsed": self.collapsed,
            "fallen": ",".join(self.fallen),
            "peak_theta_rad": self.peak_theta_rad,
            "peak_over_own_alpha": self.peak_over_own_alpha,
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, object]) -> Verdict:
        """The verdict of a record (:meth:`to_dict`; a null number is NaN)."""
        fallen = str(data.get("fallen") or "")
        return cls(
            bool(data.get("collapsed")),
            tuple(n for n in fallen.split(",") if n),
            _number(data.get("peak_theta_rad")),
            _number(data.get("peak_over_own_alpha")),
        )


def _number(value: object) -> float:
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else math.nan


def coverage_columns(coverage: Mapping[str, object] | None) -> dict[str, float]:
    """The columns of how much of the base motion a run leaves out (``meta.motion_coverage``,
    :func:`rockyade.motion.coverage.record_coverage`): the time after the scene's end, s, and
    the fraction of the motion's PGA the run never sees (0 when the run covers the motion; no
    columns without a base motion)."""
    if not coverage or "pga_left_out_fraction" not in coverage:
        return {}
    return {
        "motion_time_left_out_s": _number(coverage.get("time_left_out_s")),
        "motion_pga_left_out_fraction": _number(coverage.get("pga_left_out_fraction")),
    }


@dataclass(frozen=True)
class RunRow:
    """One run of a study (module docstring).

    Attributes
    ----------
    index
        The run's position in its study.
    name
        ``<scene hash>_<solver>`` (:func:`rockyade.runner.tasks.run_name`).
    scene_hash, solver
        The scene's hash and the solver's name.
    labels
        What names the run to a reader (the task's labels: grid values, record, level).
    status
        ``completed``, ``overturned``, ``failed`` or :data:`UNFINISHED`.
    failure_reason
        Why it failed (or did not finish); "" otherwise.
    overturn_time_s, overturned_block
        When and which block overturned first (the solver's own criterion), s.
    wall_time_s
        The solver's wall time, s (None: not measured).
    elapsed_s
        The run's share of its job's wall time in the study, s (None: not run here).
    coverage
        :func:`coverage_columns` of the run.
    verdict
        The collapse verdict (None: not asked for, or no answer).
    metrics
        The summary metrics (:func:`rockyade.analysis.metrics.summary_metrics`), empty when not
        asked for.
    duplicate_of
        The index of the run this one repeats (-1: none).
    meta
        The run's metadata (for its record; not a column).
    recorded
        Its record is written already (a run whose time history is kept writes the record
        with it, where it runs).
    result
        The run's Result, when the study keeps it in memory (not a column).
    """

    index: int
    name: str
    scene_hash: str
    solver: str
    labels: Mapping[str, Cell]
    status: str
    failure_reason: str = ""
    overturn_time_s: float | None = None
    overturned_block: str = ""
    wall_time_s: float | None = None
    elapsed_s: float | None = None
    coverage: Mapping[str, float] = field(default_factory=dict)
    verdict: Verdict | None = None
    metrics: Mapping[str, Cell] = field(default_factory=dict)
    duplicate_of: int = -1
    meta: RunMeta | None = field(default=None, compare=False, repr=False)
    recorded: bool = field(default=False, compare=False)
    result: Result | None = field(default=None, compare=False, repr=False)

    @property
    def answered(self) -> bool:
        """The run ended with an answer (completed or overturned)."""
        return self.status in ANSWERED

    @property
    def collapsed(self) -> bool | None:
        """The verdict: collapsed (True), stood (False), or none (None: failed, unfinished, or
        not asked for)."""
        return self.verdict.collapsed if self.verdict is not None and self.answered else None

    @classmethod
    def of(cls, task: Task, meta: RunMeta, elapsed_s: float | None = None) -> RunRow:
        """The row of a task's run from its Result's metadata (no verdict, no metrics yet)."""
        return cls(
            index=task.index,
            name=task.name,
            scene_hash=meta.scene_hash or task.scene_hash,
            solver=task.solver.name,
            labels=dict(task.labels),
            status=meta.status,
            failure_reason=meta.failure_reason or "",
            overturn_time_s=meta.overturn_time_s,
            overturned_block=meta.overturned_block or "",
            wall_time_s=meta.wall_time_s,
            elapsed_s=elapsed_s,
            coverage=coverage_columns(meta.motion_coverage),
            meta=meta,
        )

    @classmethod
    def placeholder(cls, task: Task, status: str, reason: str) -> RunRow:
        """The row of a run that gave no result (unfinished, or its worker died)."""
        return cls(task.index, task.name, task.scene_hash, task.solver.name, dict(task.labels), status, reason)

    def failed(self, reason: str) -> RunRow:
        """This run as failed, for ``reason`` (its answer, verdict and metrics dropped)."""
        return replace(self, status="failed", failure_reason=reason, overturn_time_s=None, overturned_block="",
                       verdict=None, metrics={})  # fmt: skip

    def summary(self) -> Cells:
        """The flat row (a batch summary's, a record's ``summary``): leading columns, labels,
        status columns, coverage, then the metrics."""
        row: Cells = {
            "index": self.index,
            "run": self.name,
            "scene_hash": self.scene_hash,
            "solver": self.solver,
            **self.labels,
            "status": self.status,
            "duplicate_of": self.duplicate_of,
            "failure_reason": self.failure_reason,
            "overturn_time_s": self.overturn_time_s,
            "overturned_block": self.overturned_block,
            "wall_time_s": self.wall_time_s,
        }
        if self.elapsed_s is not None:
            row["elapsed_s"] = self.elapsed_s
        row.update(self.coverage)
        row.update(self.metrics)
        return row

    @classmethod
    def from_record(cls, task: Task, summary: Mapping[str, Cell], verdict: Mapping[str, object] | None) -> RunRow:
        """The row of a run finished earlier, from its record (:meth:`summary`, and its
        ``verdict``), with this task's index and labels."""
        known = {*LEADING_COLUMNS, *STATUS_COLUMNS, *task.labels}
        wall = summary.get("wall_time_s")
        elapsed = summary.get("elapsed_s")
        overturn = summary.get("overturn_time_s")
        return cls(
            index=task.index,
            name=task.name,
            scene_hash=str(summary.get("scene_hash") or task.scene_hash),
            solver=task.solver.name,
            labels=dict(task.labels),
            status=str(summary.get("status")),
            failure_reason=str(summary.get("failure_reason") or ""),
            overturn_time_s=_number(overturn) if overturn is not None else None,
            overturned_block=str(summary.get("overturned_block") or ""),
            wall_time_s=_number(wall) if wall is not None else None,
            elapsed_s=_number(elapsed) if elapsed is not None else None,
            coverage={k: _number(summary.get(k)) for k in COVERAGE_COLUMNS if k in summary},
            verdict=Verdict.from_dict(verdict) if verdict is not None else None,
            metrics={k: v for k, v in summary.items() if k not in known},
        )

    def duplicate(self, task: Task) -> RunRow:
        """The row of ``task``, a grid point that repeats this run: its result, the task's own
        index and labels, and ``duplicate_of`` this run's index."""
        return replace(self, index=task.index, labels=dict(task.labels), duplicate_of=self.index, recorded=True)


__all__ = [
    "ANSWERED",
    "COVERAGE_COLUMNS",
    "LEADING_COLUMNS",
    "STATUS_COLUMNS",
    "UNFINISHED",
    "Cell",
    "Cells",
    "RunRow",
    "Verdict",
    "coverage_columns",
]
