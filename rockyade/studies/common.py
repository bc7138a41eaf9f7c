"""Pieces shared by the studies: specimen scenes, the report index and its run log,
progress bars, uplift checks and the figure conventions (one style per solver).
"""

from __future__ import annotations

import copy
import math
import re
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from rockyade import paper
from rockyade.blocks.classical import classical_parameters
from rockyade.constants import G
from rockyade.io.atomic import atomic_open, write_text

PARAMETER_SETS = ("theoretical", "experimental")
#: Scene hashes in failure reasons (file names of batch runs), replaced when grouping failures.
RUN_HASH = re.compile(r"(?<![0-9A-Za-z])[0-9a-f]{12,64}(?![0-9A-Za-z])")


def block_table(key: str, parameters: str = "experimental", name: str | None = None) -> dict[str, Any]:
    """A ``[[blocks]]`` table for a specimen of the paper.

    ``experimental``: Table 1-2 geometry with Table 3-4's E values as overrides;
    ``theoretical``: the geometry alone (alpha, p, mu from Eqs 2-4, general forms).
    """
    spec = paper.specimen(key)
    table: dict[str, Any] = {
        "name": name or spec.name,
        "vertices_m": spec.vertices().tolist(),
        "thickness_m": spec.thickness_m,
        "mass_kg": spec.mass_kg,
    }
    if parameters == "experimental":
        table.update(spec.experimental)
    return table


def block_alpha(key: str, parameters: str) -> float:
    """Critical angle of a specimen with the given parameter set, rad."""
    spec = paper.specimen(key)
    if parameters == "experimental":
        return spec.experimental["alpha_rad"]
    return classical_parameters(spec.block()).alpha_rad


def scene_dict(
    blocks: list[dict[str, Any]],
    motion: dict[str, Any],
    duration_s: float,
    sample_dt_s: float = 0.002,
    calibration: str = "matched",
    **contact: Any,
) -> dict[str, Any]:
    """A scene dictionary."""
    return {
        "duration_s": round(float(duration_s), 6),
        "sample_dt_s": sample_dt_s,
        "blocks": copy.deepcopy(blocks),
        "contact": {"calibration": calibration, **contact},
        "motion": copy.deepcopy(motion),
    }


def biblock_blocks(parameters: str = "experimental") -> list[dict[str, Any]]:
    """The bi-block structure, lower block first (Table 2)."""
    return [block_table("lower", parameters), block_table("upper", parameters)]


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
        self.record(
            run, str(result.meta.get("solver", "?")), result.status, str(result.meta.get("failure_reason") or "")
        )

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


# ---------------------------------------------------------------------- progress
def progress(total: int, desc: str) -> Any:
    """A tqdm progress bar on stderr (``update(1)`` per finished run)."""
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, unit="run", smoothing=0.05, leave=True)


def run_each(items: Sequence[Any], fn: Callable[[Any], Any], desc: str) -> list[Any]:
    """``[fn(item) for item in items]`` with a progress bar."""
    out = []
    with progress(len(items), desc) as bar:
        for item in items:
            out.append(fn(item))
            bar.update(1)
    return out


def run_yade(scenes: Sequence[Any], workers: int, desc: str) -> list[Any]:
    """YADE runs in parallel with a progress bar; a failed run is a failed Result, never an exception."""
    from rockyade.solvers import yade as yade_backend

    results: list[Any] = [None] * len(scenes)
    with progress(len(scenes), desc) as bar, ThreadPoolExecutor(max_workers=max(1, workers)) as pool:
        futures = {pool.submit(yade_backend.run_many, [scene], 1): i for i, scene in enumerate(scenes)}
        for future in as_completed(futures):
            results[futures[future]] = future.result()[0]
            bar.update(1)
    return results


# ---------------------------------------------------------------------- uplift
@dataclass(frozen=True)
class Uplift:
    """The smallest horizontal base acceleration that lifts a block of a column (statics).

    Attributes
    ----------
    accel_m_s2
        Uplift acceleration of the weakest mechanism, m/s^2.
    mechanism
        Which blocks rock, as one body, on which joint.
    """

    accel_m_s2: float
    mechanism: str


def uplift_acceleration(scene: Any) -> Uplift:
    """Smallest uplift acceleration of a column of blocks (bottom to top).

    Each mechanism is blocks k..n rocking as one rigid body about a corner of block k's
    base: a_up = g (b_k - |x_c - x_k|) / h_c, with b_k = h_k tan(alpha_k) the half base of
    block k (its alpha, overrides included: paper Eq 11's equivalent base), x_k its
    centroid, and (x_c, h_c) the centroid of blocks k..n above that base. For one block
    this is Housner's g tan(alpha). A rigid column subject to a smaller acceleration does
    not rock; a sequence of mechanisms of two moving bodies needs at least the smaller of
    its two single-body values (the ratio of work terms is smallest on an extreme ray).
    """
    blocks = list(scene.blocks)
    best = Uplift(math.inf, "")
    base_y = np.cumsum([0.0] + [b.block().height_m for b in blocks])
    for k, spec in enumerate(blocks):
        params = spec.classical()
        cx_k = spec.block().centroid_m[0] + spec.x_offset_m
        half_base = params.centroid_height_m * math.tan(params.alpha_rad)
        masses, xs, ys = [], [], []
        for j in range(k, len(blocks)):
            geo = blocks[j].block()
            masses.append(geo.mass_kg)
            xs.append(geo.centroid_m[0] + blocks[j].x_offset_m)
            ys.append(base_y[j] - base_y[k] + geo.centroid_m[1] - geo.vertices_m[:, 1].min())
        m = np.asarray(masses)
        x_c, h_c = float(np.dot(m, xs) / m.sum()), float(np.dot(m, ys) / m.sum())
        accel = G * (half_base - abs(x_c - cx_k)) / h_c
        if accel < best.accel_m_s2:
            names = [b.name for b in blocks[k:]]
            on = "the base" if k == 0 else blocks[k - 1].name
            who = names[0] if len(names) == 1 else " + ".join(names) + " as one body"
            best = Uplift(accel, f"{who} rocking on {on}")
    return best


def peak_base_acceleration(scene: Any) -> float:
    """Largest |horizontal base acceleration| of a scene's motion, m/s^2 (0 for free rocking)."""
    gm = scene.motion.ground_motion(scene.duration_s)
    return 0.0 if gm is None else float(np.max(np.abs(gm.ah_m_s2)))


def no_uplift_note(scene: Any, results: dict[str, Any]) -> str:
    """A sentence saying that the base never lifts a block, or "" when it may.

    Compares the largest base acceleration with :func:`uplift_acceleration` and quotes
    the largest |theta| / alpha the solvers gave (the DEMs' tilt of elastic contacts).
    """
    uplift = uplift_acceleration(scene)
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


# ---------------------------------------------------------------------- figure styles
#: One look per solver in every study figure. The reference DEM is a wide translucent
#: band, Housner a thin solid line and YADE a dashed line on top, so that curves that
#: coincide stay visible (a dashed line inside a band) instead of hiding each other.
SOLVER_STYLES: dict[str, dict[str, Any]] = {
    "reference": {"color": "#f28e2b", "lw": 4.0, "alpha": 0.45, "ls": "-", "zorder": 2},
    "housner": {"color": "#1f4e9c", "lw": 1.0, "alpha": 1.0, "ls": "-", "zorder": 3},
    "yade": {"color": "#1b7837", "lw": 1.3, "alpha": 1.0, "ls": (0, (4, 3)), "zorder": 4},
}
SOLVER_LABELS = {"housner": "Housner (exact)", "reference": "reference DEM", "yade": "YADE"}


def plot_solver(ax: Any, solver: str, t: Any, y: Any, label: str | None = None) -> None:
    """Draw one solver's curve in its study style."""
    ax.plot(t, y, label=label or SOLVER_LABELS.get(solver, solver), **SOLVER_STYLES[solver])


def max_difference(a: Any, b: Any, block: str | None = None, quantity: str = "theta_rad") -> float:
    """max |a - b| of a quantity over the samples both results have (same sampling)."""
    ya, yb = a.series(quantity, block), b.series(quantity, block)
    n = min(ya.size, yb.size)
    return float(np.max(np.abs(ya[:n] - yb[:n]))) if n else math.nan


def fmt(value: float, digits: int = 4) -> str:
    """Compact number for captions (NaN as n/a)."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "n/a"
    return f"{value:.{digits}g}"


def shade_harmonic_states(ax, phases: dict[str, float], t_end: float, settle_cycles: float, frequency: float) -> None:
    """Shade the transient, stationary and free-rocking states of a harmonic test."""
    transient_end = phases["ramp_up_end_s"] + settle_cycles / frequency
    spans = (
        (0.0, transient_end, "transient", "#f2d7b6"),
        (transient_end, phases["end_s"], "stationary", "#d4e6f1"),
        (phases["end_s"], t_end, "free rocking", "#d5f5e3"),
    )
    for start, end, label, colour in spans:
        if end > start:
            ax.axvspan(start, end, color=colour, alpha=0.5, lw=0, label=label)
