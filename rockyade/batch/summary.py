"""A batch's summary: one row per run, the rows of runs finished earlier (resume), and
``summary.csv`` (with ``summary.parquet`` when pyarrow is installed) written as one set.

A row holds the run's name, the grid values (the task's labels), its status, failure
reason, wall time and metrics (:func:`rockyade.analysis.metrics.summary_metrics`). A run's
row is also in its record (``runs/<name>.json``, :mod:`rockyade.runner.journal`), which is
what ``resume`` reads back. The summary is sorted by run order, its columns in one order,
so that the same inputs give the same summary on any executor (wall times aside).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pandas as pd

from rockyade.errors import os_error_message
from rockyade.io.resultset import replacing_set
from rockyade.run_meta import RunMeta
from rockyade.runner import Task
from rockyade.runner.journal import read_run

#: Columns that differ between equal runs (wall-clock times).
TIMING_COLUMNS = ("wall_time_s", "elapsed_s")
#: Status of a run that a Ctrl-C stopped or kept from starting (summary only).
UNFINISHED = "unfinished"
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
#: The summary's files: written together (:func:`rockyade.io.resultset.replacing_set`), the CSV last.
SUMMARY_FILES = ("summary.parquet", "summary.csv")


def run_name(scene_hash: str, solver: str) -> str:
    """File stem of a run: ``<scene hash>_<solver>``."""
    return f"{scene_hash}_{solver}"


def task_run_name(task: Task) -> str:
    """File stem of a task's run."""
    return run_name(task.scene_hash, task.solver.name)


def coverage_columns(coverage: Mapping[str, Any] | None) -> dict[str, Any]:
    """The summary's columns of how much of the base motion a run leaves out
    (``meta.motion_coverage``, :func:`rockyade.motion.coverage.record_coverage`): the time
    after the scene's end, s, and the fraction of the motion's PGA the run never sees (0 when
    the run covers the motion; no columns without a base motion)."""
    if not coverage or "pga_left_out_fraction" not in coverage:
        return {}
    return {
        "motion_time_left_out_s": coverage["time_left_out_s"],
        "motion_pga_left_out_fraction": coverage["pga_left_out_fraction"],
    }


def status_row(task: Task, meta: RunMeta) -> dict[str, Any]:
    """The row's leading and status columns of a run from its Result's metadata."""
    return {
        "index": task.index,
        "run": task_run_name(task),
        "scene_hash": meta.scene_hash,
        "solver": task.solver.name,
        **task.labels,
        "status": meta.status,
        "failure_reason": meta.failure_reason or "",
        "overturn_time_s": meta.overturn_time_s,
        "overturned_block": meta.overturned_block or "",
        "wall_time_s": meta.wall_time_s,
        **coverage_columns(meta.motion_coverage),
    }


def write_failure_row(task: Task, row: Mapping[str, Any], exc: OSError) -> dict[str, Any]:
    """The row of a run whose result could not be written (no file of it is left half-written)."""
    keep = (
        *LEADING_COLUMNS,
        *task.labels,
        "wall_time_s",
        "elapsed_s",
        "motion_time_left_out_s",
        "motion_pga_left_out_fraction",
    )
    return {
        **{k: v for k, v in row.items() if k in keep},
        "status": "failed",
        "failure_reason": f"cannot write the result: {os_error_message(exc)}",
        "overturn_time_s": None,
        "overturned_block": "",
    }


def completed_row(task: Task, runs: Path) -> dict[str, Any] | None:
    """The row of a run already completed (or overturned) for the same scene, from its
    record in ``runs`` (:func:`rockyade.runner.journal.read_run`), with this task's index
    and labels; None: it is to be run."""
    row = read_run(runs, task_run_name(task), task.scene_hash)
    if row is None:
        return None
    row["index"] = task.index
    row.update(task.labels)
    return row


def placeholder_row(task: Task, status: str, reason: str) -> dict[str, Any]:
    """A row for a run that produced no result (unfinished, or its worker died)."""
    return {
        "index": task.index,
        "run": task_run_name(task),
        "scene_hash": task.scene_hash,
        "solver": task.solver.name,
        **task.labels,
        "status": status,
        "failure_reason": reason,
        "overturn_time_s": None,
        "overturned_block": "",
        "wall_time_s": None,
    }


def duplicate_row(task: Task, original: Mapping[str, Any]) -> dict[str, Any]:
    """The row of a grid point that repeats an earlier one: its result, its own grid values,
    and ``duplicate_of`` the index of the row it repeats."""
    return {**original, "index": task.index, **task.labels, "duplicate_of": original["index"]}


def failure_line(row: Mapping[str, Any]) -> str | None:
    """``failed: <run>: <reason>`` for a failed run's row; None for the others."""
    return f"failed: {row['run']}: {row['failure_reason']}" if row["status"] == "failed" else None


def summary_frame(rows: list[dict[str, Any]], labels: list[str]) -> pd.DataFrame:
    """The summary of ``rows``: sorted by run order, columns in one canonical order (fresh,
    resumed or Dask rows alike): leading, the grid's ``labels``, status, then the rest sorted."""
    for row in rows:
        row.setdefault("duplicate_of", -1)
    summary = pd.DataFrame(rows).sort_values("index").reset_index(drop=True)
    first = [c for c in (*LEADING_COLUMNS, *labels, *STATUS_COLUMNS) if c in summary.columns]
    rest = sorted(c for c in summary.columns if c not in first)
    return summary[first + rest]


def write_summary(summary: pd.DataFrame, out: Path) -> None:
    """``summary.csv`` (and ``summary.parquet`` when pyarrow is installed) in ``out``, replaced
    as one set, fsynced (:func:`rockyade.io.resultset.replacing_set`: the previous pair or the
    new one, never one of each). The caller holds ``out``'s lock."""
    with replacing_set(out, SUMMARY_FILES, last="summary.csv") as stage:
        with open(stage / "summary.csv", "w", newline="") as fh:
            summary.to_csv(fh, index=False, float_format="%.10g", lineterminator="\n")
        if _has_pyarrow():
            summary.to_parquet(stage / "summary.parquet", index=False)


def _has_pyarrow() -> bool:
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        return False
    return True


def failures(summary: pd.DataFrame) -> pd.DataFrame:
    """Rows of failed runs with their reasons."""
    return summary.loc[summary["status"] == "failed", ["run", "solver", "failure_reason"]]


def comparable(summary: pd.DataFrame) -> pd.DataFrame:
    """The summary without timing columns (equal for equal inputs on any executor)."""
    return summary.drop(columns=[c for c in TIMING_COLUMNS if c in summary.columns])


__all__ = [
    "SUMMARY_FILES",
    "TIMING_COLUMNS",
    "UNFINISHED",
    "comparable",
    "completed_row",
    "failures",
    "run_name",
    "status_row",
    "summary_frame",
    "write_summary",
]
