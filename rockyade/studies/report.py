"""The report a study writes: its index with sections, tables and figures, the log of every
run (so that a failed run is counted, listed and never passes unnoticed), failures grouped
by cause, and the numbers and sentences of its captions."""

from __future__ import annotations

import math
import os
import re
import resource
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from rockyade.dem.statics import column_uplift
from rockyade.io.atomic import atomic_open, write_text

#: Scene hashes in failure reasons (file names of batch runs), replaced when grouping failures.
RUN_HASH = re.compile(r"(?<![0-9A-Za-z])[0-9a-f]{12,64}(?![0-9A-Za-z])")


@dataclass(frozen=True)
class RunRecord:
    """One run of a study: which part, what was run, by which solver, and how it ended."""

    part: str
    run: str
    solver: str
    status: str
    reason: str = ""


@dataclass
class Report:
    """The report being written: files in ``out``, an index with captions, and a log of
    every run (so that a failed run is counted, listed and never passes unnoticed).

    ``part`` is the study part now running; sections and runs are filed under it.
    """

    out: Path
    sections: list[tuple[str, list[str]]] = field(default_factory=list)
    runs: list[RunRecord] = field(default_factory=list)
    part: str = ""
    section_parts: list[str] = field(default_factory=list)
    index_path: Path | None = None

    def section(self, title: str, intro: str = "") -> None:
        """Start a section of the index (filed under the current part)."""
        self.sections.append((title, [intro] if intro else []))
        self.section_parts.append(self.part)

    def table(self, name: str, frame: pd.DataFrame, caption: str, float_format: str = "%.6g") -> Path:
        """Write a CSV and index it."""
        path = self.out / name
        with atomic_open(path) as fh:
            frame.to_csv(fh, index=False, float_format=float_format, lineterminator="\n")
        self.sections[-1][1].append(f"- **Table** [`{name}`]({name}): {caption}")
        return path

    def figure(self, name: str, caption: str) -> Path:
        """Index a figure (written by the caller at ``out / name``)."""
        self.sections[-1][1].append(f"![{caption}]({name})\n\n*{name}*: {caption}\n")
        return self.out / name

    def note(self, text: str) -> None:
        """A paragraph in the current section."""
        self.sections[-1][1].append(text)

    # ------------------------------------------------------------------ run log
    def record(self, run: str, solver: str, status: str, reason: str = "") -> None:
        """Log one run of the current part (status completed | overturned | failed | ...)."""
        self.runs.append(RunRecord(self.part, run, solver, status, reason))

    def record_result(self, run: str, result: Any) -> None:
        """Log a :class:`~rockyade.result.Result`."""
        self.record(run, str(result.meta.solver or "?"), result.status, str(result.meta.failure_reason or ""))

    def record_summary(self, summary: pd.DataFrame, label: Callable[[pd.Series], str]) -> None:
        """Log every row of a batch summary (columns ``solver``, ``status``, ``failure_reason``)."""
        for _, row in summary.iterrows():
            reason = row.get("failure_reason")
            reason = "" if reason is None or (isinstance(reason, float) and math.isnan(reason)) else str(reason)
            self.record(label(row), str(row["solver"]), str(row["status"]), reason)

    def failures(self, part: str | None = None) -> list[RunRecord]:
        """Failed runs (of one part, or of all)."""
        return [r for r in self.runs if r.status == "failed" and (part is None or r.part == part)]

    def counts(self, part: str | None = None, solver: str | None = None) -> dict[str, int]:
        """Runs per status, of one part and solver (or all)."""
        out: dict[str, int] = {}
        for r in self.runs:
            if (part is None or r.part == part) and (solver is None or r.solver == solver):
                out[r.status] = out.get(r.status, 0) + 1
        return out

    def failure_groups(self, part: str | None = None) -> list[tuple[str, str, str, list[str]]]:
        """Failed runs grouped by (part, solver, reason): ``[(part, solver, reason, runs)]``."""
        groups: dict[tuple[str, str, str], list[str]] = {}
        for r in self.failures(part):
            # the same cause names each run's own files (hash-named): group on the rest
            reason = RUN_HASH.sub("<hash>", r.reason) if r.reason else "no reason given"
            groups.setdefault((r.part, r.solver, reason), []).append(r.run)
        return [(p, s, reason, runs) for (p, s, reason), runs in groups.items()]

    def close_part(self, part: str) -> None:
        """Append the part's run count and its failed runs (grouped by cause) to the part's last section."""
        runs = [r for r in self.runs if r.part == part]
        if not runs or part not in self.section_parts:
            return
        index = len(self.section_parts) - 1 - self.section_parts[::-1].index(part)
        items = self.sections[index][1]
        summary = ", ".join(f"{v} {k}" for k, v in sorted(self.counts(part).items()))
        failed = self.failures(part)
        if not failed:
            items.append(f"**Runs:** {len(runs)} ({summary}); none failed.")
            return
        lines = [f"**Runs:** {len(runs)} ({summary}). **{len(failed)} FAILED** (each in `failed_runs.csv`):", ""]
        lines += [
            f"- {describe_failures(solver, reason, names)}" for _, solver, reason, names in self.failure_groups(part)
        ]
        items.append("\n".join(lines))

    def write_index(self, title: str, preamble: str) -> Path:
        """``index.md`` with a status line, every section, and ``failed_runs.csv``."""
        failed = self.failures()
        status = (
            f"**Status: all {len(self.runs)} runs ended without failure.**"
            if not failed
            else f"**Status: {len(failed)} of {len(self.runs)} runs FAILED** ("
            + ", ".join(f"{p}: {n}" for p, n in _per_part(failed).items())
            + "): see each part below and `failed_runs.csv`. Results that need them are missing or partial."
        )
        frame = pd.DataFrame([r.__dict__ for r in failed], columns=["part", "run", "solver", "status", "reason"])
        with atomic_open(self.out / "failed_runs.csv") as fh:
            frame.to_csv(fh, index=False, lineterminator="\n")
        lines = [f"# {title}", "", preamble, "", status, ""]
        for heading, items in self.sections:
            lines += [f"## {heading}", ""]
            for item in items:
                lines += [item, ""]
        self.index_path = self.out / "index.md"
        write_text(self.index_path, "\n".join(lines))
        return self.index_path


def cpu_seconds() -> float:
    """CPU time, user + system, s, of this process and of every process below it: the finished
    ones (the workers of each batch, the solvers' programs they waited for) and the ones still
    running (a warm YADE or Siconos program kept between runs, read from ``/proc`` where there is
    one): a part's cost on an idle machine, which a loaded one hides in its wall time. Not
    counted: a program whose parent ended without waiting for it (the warm YADE and Siconos
    programs of a batch's workers, which end with their worker): its time is lost to every
    parent, so YADE's and Siconos's runs are missing from the figure."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime + _running_descendants_cpu()


def _running_descendants_cpu() -> float:
    """CPU time of the processes below this one that still run, with their own finished
    children's (``/proc/<pid>/stat``: utime, stime, cutime, cstime), s; 0 without ``/proc``."""
    proc = Path("/proc")
    if not (proc / "self" / "stat").is_file():
        return 0.0
    tree: dict[int, list[tuple[int, float]]] = {}
    tick = os.sysconf("SC_CLK_TCK")
    for stat in proc.glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):  # a process that ended meanwhile
            continue
        ppid, times = int(fields[1]), sum(int(v) for v in fields[11:15]) / tick
        tree.setdefault(ppid, []).append((int(stat.parent.name), times))
    total, todo = 0.0, [os.getpid()]
    while todo:
        for pid, times in tree.get(todo.pop(), []):
            total += times
            todo.append(pid)
    return total


def describe_failures(solver: str, reason: str, runs: Sequence[str], shown: int = 3) -> str:
    """One line for failed runs that share a solver and a reason."""
    names = "; ".join(runs[:shown]) + (f"; and {len(runs) - shown} more" if len(runs) > shown else "")
    return f"{solver}, {len(runs)} run(s) ({names}): {reason}"


def _per_part(records: Iterable[RunRecord]) -> dict[str, int]:
    out: dict[str, int] = {}
    for r in records:
        out[r.part] = out.get(r.part, 0) + 1
    return out


def run_state(report: Report, solver: str, runs: int) -> str:
    """How a solver's runs of the current part ended, in words, e.g. "all 30 failed"."""
    counts = report.counts(report.part, solver)
    failed = counts.get("failed", 0)
    if runs and failed == runs:
        return f"all {runs} runs failed"
    return f"{runs - failed} of {runs} runs succeeded" if failed else f"all {runs} runs succeeded"


# ---------------------------------------------------------------------- captions
def fmt(value: float, digits: int = 4) -> str:
    """Compact number for captions (NaN as n/a)."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "n/a"
    return f"{value:.{digits}g}"


def max_difference(a: Any, b: Any, block: str | None = None, quantity: str = "theta_rad") -> float:
    """max |a - b| of a quantity over the samples both results have (same sampling)."""
    ya, yb = a.series(quantity, block), b.series(quantity, block)
    n = min(ya.size, yb.size)
    return float(np.max(np.abs(ya[:n] - yb[:n]))) if n else math.nan


def peak_base_acceleration(scene: Any) -> float:
    """Largest |horizontal base acceleration| of a scene's motion, m/s^2 (0 for free rocking)."""
    gm = scene.motion.ground_motion(scene.duration_s)
    return 0.0 if gm is None else float(np.max(np.abs(gm.ah_m_s2)))


def no_uplift_note(scene: Any, results: dict[str, Any]) -> str:
    """A sentence saying that the base never lifts a block, or "" when it may.

    Compares the largest base acceleration with :func:`~rockyade.dem.statics.column_uplift` and quotes
    the largest |theta| / alpha the solvers gave (the DEMs' tilt of elastic contacts).
    """
    uplift = column_uplift(scene)
    peak = peak_base_acceleration(scene)
    if not peak < uplift.accel_m_s2:
        return ""
    tilts = []
    for r in results.values():
        if r.ok:
            for spec in scene.blocks:
                tilts.append(float(np.max(np.abs(r.series("theta_rad", spec.name)))) / spec.classical().alpha_rad)
    tilt = f" The solvers' largest |theta| / alpha is {max(tilts):.1g} (elastic contact tilt)." if tilts else ""
    return (
        f"No uplift: the largest base acceleration, {peak:.3g} m/s^2, is {peak / uplift.accel_m_s2:.2f} of the "
        f"uplift acceleration {uplift.accel_m_s2:.3g} m/s^2 ({uplift.mechanism}): a rigid block does not rock.{tilt}"
    )
