"""``rockyade crosscheck``: several solvers on one scene over a record set, compared by their
collapse intensities (the statistics: :mod:`rockyade.analysis.crosscheck`; the method and
what was measured: docs/verification.md).

For each solver, each time-step factor (1, and 0.5 for the convergence check) and each
record, a collapse search: the scan's levels (from the scene's static collapse acceleration,
as ``rockyade fragility`` chooses its stripes, :func:`rockyade.assess.fragility.fragility_plan`),
then bisection to the resolution. The searches advance together, one round at a time; each
round's runs go through the batch machinery (:func:`rockyade.studies.batch.run_study_tasks`:
the runner's executors, grouped runs, a JSON per finished run written as it ends, Ctrl-C).

Files. The study works in ``<out>.partial/`` beside ``--out``: ``plan.json`` (what the study
is), ``dt<f>/runs/`` (one JSON per finished run, by scene hash and solver, one folder per
time-step factor) and, after Ctrl-C, a summary marked PARTIAL. When every search is done,
the summary is written there (``collapse_intensities.csv``, ``pairs.csv``, ``runs.csv``,
``crosscheck.json``, ``crosscheck.png``, ``index.md``) and the folder replaces ``--out`` as a
whole (the old set renamed aside, the new one renamed in, the old one removed): a crash
leaves the previous complete set or the new one, never a mix (:func:`settle` finishes a swap
that a kill cut short).

Resume. Every search is a function of its outcomes, so ``--resume`` replays the searches
from the runs on disk and runs only what is missing (a run that failed is run again); after
Ctrl-C or kill -9 no finished run is repeated. Without ``--resume`` an unfinished study in
``<out>.partial/`` is discarded and the study starts afresh; with it, a study whose plan
differs is refused.
"""

from __future__ import annotations

import itertools
import json
import math
import os
import secrets
import shutil
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from rockyade.analysis.crosscheck import (
    BRACKETED,
    RESOLUTION,
    TOLERANCE,
    CollapseSearch,
    MedianInterval,
    collapse_summary,
    median_interval,
    next_levels,
    pair_verdict,
    paired_ratios,
    verdict_agreement,
)
from rockyade.assess.fragility import FragilityPlan, fragility_plan
from rockyade.assess.measures import Measure
from rockyade.assess.motions import MotionSet
from rockyade.assess.stripes import MAX_LOAD_FACTOR, collapse_rule
from rockyade.errors import BatchInterruptedError, InputError
from rockyade.io.atomic import atomic_open, fsync_dir, write_json, write_text
from rockyade.io.locking import DIR_LOCK_NAME, output_lock
from rockyade.runner import Executor
from rockyade.scene import Scene
from rockyade.solvers import make_solver, solver_class, solver_names
from rockyade.solvers.base import Solver
from rockyade.studies.batch import MAX_RUNS, BatchTask, batch_task, run_name, run_study_tasks

#: Time-step factors by default: the solver's own step, and half of it (convergence).
DT_FACTORS = (1.0, 0.5)
#: The files of a complete set.
RESULT_FILES = ("collapse_intensities.csv", "pairs.csv", "runs.csv", "crosscheck.json", "crosscheck.png", "index.md")
#: Suffix of the working folder beside --out.
PARTIAL_SUFFIX = ".partial"


@dataclass(frozen=True)
class CrosscheckPlan:
    """What a cross-check runs (see :func:`crosscheck_plan`).

    Attributes
    ----------
    stripes
        The fragility plan whose scene, records, measure, levels and load factors it shares.
    solvers
        Solver names, in order.
    dt_factors
        Time-step factors, the first the reference (1).
    resolution
        Bisection to a bracket of ratio 1 + resolution.
    tolerance
        Median ratio within 1 +/- tolerance (interval within twice it) counts as agreement.
    records_per_solver
        Solver -> how many of the records it runs (the first ones; absent: all).
    solver_options
        Options every solver taking them gets (e.g. YADE's ``timeout_s``).
    """

    stripes: FragilityPlan
    solvers: tuple[str, ...]
    dt_factors: tuple[float, ...] = DT_FACTORS
    resolution: float = RESOLUTION
    tolerance: float = TOLERANCE
    records_per_solver: Mapping[str, int] = field(default_factory=dict)
    solver_options: Mapping[str, Any] = field(default_factory=dict)

    @property
    def measure(self) -> Measure:
        """The intensity measure."""
        return self.stripes.measure

    @property
    def scene(self) -> Scene:
        """The scene (its motion replaced in every run)."""
        return self.stripes.stripes.scene

    @property
    def motions(self) -> MotionSet:
        """The records."""
        return self.stripes.stripes.motions

    @property
    def scan_si(self) -> tuple[float, ...]:
        """The scan's levels, SI."""
        return tuple(self.stripes.levels_si)

    def records_of(self, solver: str) -> range:
        """The record indices ``solver`` runs."""
        return range(min(self.motions.count, self.records_per_solver.get(solver, self.motions.count)))

    def solver(self, name: str, dt_factor: float) -> Solver:
        """The solver ``name`` at ``dt_factor`` with the options it takes."""
        return _solver(name, dt_factor, self.solver_options)

    def searches(self) -> list[tuple[str, float, int]]:
        """Every (solver, dt factor, record index) searched."""
        return [(s, f, i) for f in self.dt_factors for s in self.solvers for i in self.records_of(s)]

    def identity(self) -> dict[str, Any]:
        """What makes two studies the same (a resume must match it): everything that
        decides which runs are made."""
        plan = self.stripes.stripes
        return {
            "scene_hash": self.scene.scene_hash,
            "motions": self.motions.to_dict(),
            "measure": self.measure.to_dict(),
            "scan_si": list(self.scan_si),
            "solvers": list(self.solvers),
            "dt_factors": list(self.dt_factors),
            "resolution": self.resolution,
            "records_per_solver": dict(self.records_per_solver),
            "solver_options": {k: str(v) for k, v in self.solver_options.items()},
            "fallen_blocks": plan.fallen_blocks,
            "sample_dt_s": plan.sample_dt_s,
            "tail_s": plan.tail_s,
        }

    def expected_runs(self) -> int:
        """Runs the study is expected to make: per search the scan and the bisection from
        the scan's step to the resolution (extensions beyond the levels not counted)."""
        scan = sorted(self.scan_si)
        step = max(b / a for a, b in itertools.pairwise(scan)) if len(scan) > 1 else 2.0
        bisections = max(0, math.ceil(math.log2(math.log(step) / math.log1p(self.resolution))))
        return len(self.searches()) * (len(scan) + bisections)

    def cost_line(self, workers: int) -> str:
        """The study's expected runs and time, before anything runs."""
        plan = self.stripes.stripes
        longest = int(np.argmax(plan.durations_s))
        top = max(self.scan_si)
        scene = plan.scene_for(longest, plan.load_factor(longest, top))
        per_search = self.expected_runs() / max(1, len(self.searches()))
        seconds = 0.0
        for s, f, _i in self.searches():
            seconds += self.solver(s, f).estimate_cost(scene).wall_time_s * per_search
        return (
            f"cost: about {self.expected_runs()} runs ({len(self.searches())} searches of {per_search:.0f} runs: "
            f"{len(self.scan_si)} scan levels, then bisection to {100 * self.resolution:g} %), "
            f"about {_duration(seconds / max(1, workers))} on {workers} worker(s) by the solvers' estimates"
        )


def _solver(name: str, dt_factor: float, solver_options: Mapping[str, Any]) -> Solver:
    """Solver ``name`` at ``dt_factor`` (an option only when not 1) with the options it takes."""
    options = {k: v for k, v in solver_options.items() if k in solver_class(name).OPTIONS}
    if dt_factor != 1.0:
        options["dt_factor"] = dt_factor
    return make_solver(name, **options)


def _duration(seconds: float) -> str:
    if seconds < 120:
        return f"{seconds:.2g} s"
    if seconds < 7200:
        return f"{seconds / 60:.2g} min"
    return f"{seconds / 3600:.3g} h"


def parse_solvers(text: str, field_name: str = "--solvers") -> tuple[str, ...]:
    """``housner,reference`` as solver names: known, distinct, at least two."""
    names = tuple(s.strip() for s in str(text).split(",") if s.strip())
    known = solver_names()
    bad = [n for n in names if n not in known]
    if bad or len(set(names)) != len(names) or len(names) < 2:
        raise InputError(
            field_name, f"must be at least two distinct solvers among {', '.join(known)}, comma-separated, got {text!r}"
        )
    return names


def check_dt_factors(values: Sequence[float], field_name: str = "--dt-factors") -> tuple[float, ...]:
    """Distinct factors in (0, 1], the first 1 (the solvers' own steps)."""
    out = tuple(float(v) for v in values)
    if not out or out[0] != 1.0 or len(set(out)) != len(out) or any(not (0.0 < v <= 1.0) for v in out):
        raise InputError(
            field_name, f"must be distinct factors in (0, 1] on the solvers' time steps, the first 1, got {values!r}"
        )
    return out


def crosscheck_plan(
    scene: Scene,
    motions: MotionSet,
    measure: Measure,
    solvers: Sequence[str],
    *,
    levels: Sequence[float] | None = None,
    dt_factors: Sequence[float] = DT_FACTORS,
    resolution: float = RESOLUTION,
    tolerance: float = TOLERANCE,
    records_per_solver: Mapping[str, int] | None = None,
    solver_options: Mapping[str, Any] | None = None,
    executor: Executor | None = None,
    fallen_blocks: int = 1,
    sample_dt_s: float = 0.01,
    tail_s: float = 5.0,
    progress: bool = True,
    allow_large: bool = False,
) -> CrosscheckPlan:
    """Check the inputs, measure the records and choose the scan; nothing runs yet.

    Parameters
    ----------
    scene, motions, measure
        As :func:`rockyade.assess.fragility.fragility_plan` takes them.
    solvers
        Solver names (at least two).
    levels
        The scan's levels in the measure's shown unit (default: the fragility's stripes).
    dt_factors
        Time-step factors (default 1 and 0.5).
    resolution
        Bisection resolution, in (0.001, 0.5].
    tolerance
        Tolerance on a median ratio, in (0, 0.5].
    records_per_solver
        Solver -> records it runs (the first ones).
    solver_options
        Options for the solvers that take them.
    allow_large
        Go beyond :data:`rockyade.studies.batch.MAX_RUNS` expected runs.

    Raises
    ------
    InputError
        A bad option (named), a solver that cannot change its time step, a record that
        cannot be scaled to the levels, a study above the run limit.
    """
    names = tuple(solvers)
    factors = check_dt_factors(dt_factors)
    if not (math.isfinite(resolution) and 0.001 <= resolution <= 0.5):
        raise InputError("--resolution", f"must be in [0.001, 0.5] (a fraction of the level), got {resolution!r}")
    if not (math.isfinite(tolerance) and 0.0 < tolerance <= 0.5):
        raise InputError("--tolerance", f"must be in (0, 0.5] (a fraction), got {tolerance!r}")
    if len(factors) > 1:
        lacking = [n for n in names if "dt_factor" not in solver_class(n).OPTIONS]
        if lacking:
            raise InputError(
                "--dt-factors", f"the {', '.join(lacking)} solver has no dt_factor option: pass --dt-factors 1"
            )
    for name, count in (records_per_solver or {}).items():
        if name not in names or isinstance(count, bool) or not isinstance(count, int) or count < 1:
            raise InputError("records_per_solver", f"{name}: must be a solver run and a count >= 1, got {count!r}")
    options = dict(solver_options or {})
    for name in names:  # every solver's options checked now
        for f in factors:
            _solver(name, f, options)
    stripes = fragility_plan(
        scene,
        motions,
        measure,
        names[0],
        levels=levels,
        extend=False,
        executor=executor,
        fallen_blocks=fallen_blocks,
        sample_dt_s=sample_dt_s,
        tail_s=tail_s,
        progress=progress,
    )
    plan = CrosscheckPlan(stripes, names, factors, resolution, tolerance, dict(records_per_solver or {}), options)
    expected = plan.expected_runs()
    if expected > MAX_RUNS and not allow_large:
        raise InputError(
            "--allow-large",
            f"the cross-check is expected to make {expected:,} runs, more than the limit of {MAX_RUNS:,}: fewer "
            "records, solvers or levels, or pass --allow-large",
        )
    return plan


# ---------------------------------------------------------------------- the folders


def partial_dir(out: Path) -> Path:
    """The working folder of a cross-check writing ``out``."""
    return out.parent / f"{out.name}{PARTIAL_SUFFIX}"


def _complete(folder: Path) -> bool:
    """The folder holds a complete cross-check set (its JSON says so)."""
    try:
        data = json.loads((folder / "crosscheck.json").read_text())
    except (OSError, ValueError):
        return False
    return isinstance(data, dict) and data.get("partial") is False


def settle(out: Path) -> None:
    """Finish a swap that a kill cut short (module docstring): a complete new set waiting in
    ``<out>.partial`` goes in; else an old set renamed aside comes back; old sets are removed."""
    stage = partial_dir(out)
    olds = sorted(p for p in out.parent.glob(f".{out.name}.old-*") if p.is_dir() and not p.is_symlink())
    if not out.exists():
        if stage.is_dir() and not stage.is_symlink() and _complete(stage):
            os.rename(stage, out)
        elif olds:
            os.rename(olds.pop(), out)
        fsync_dir(out.parent)
    for old in olds:
        shutil.rmtree(old, ignore_errors=True)


def check_out(out: Path) -> None:
    """Refuse an ``--out`` that a swap would destroy: a link, a file, or a folder of other
    files than a cross-check's set (InputError naming ``--out``)."""
    for path in (out, partial_dir(out)):
        if path.is_symlink():
            raise InputError("--out", f"{path} is a symbolic link; give a real folder")
        if path.exists() and not path.is_dir():
            raise InputError("--out", f"{path} is a file; give a folder")
    if out.is_dir() and any(True for _ in out.iterdir()) and not (out / "crosscheck.json").is_file():
        raise InputError(
            "--out",
            f"{out} holds files that are not a cross-check's result (no crosscheck.json): it would be "
            "replaced as a whole; give a new or empty folder",
        )


def _swap(stage: Path, out: Path) -> None:
    """Put the complete set of ``stage`` in place of ``out`` (module docstring)."""
    old = out.parent / f".{out.name}.old-{secrets.token_hex(4)}"
    if out.exists():
        os.rename(out, old)
    os.rename(stage, out)
    fsync_dir(out.parent)
    if old.exists():
        shutil.rmtree(old, ignore_errors=True)


# ---------------------------------------------------------------------- running


@dataclass
class Outcomes:
    """Every run's verdict so far: (solver, dt factor, record index) -> level (SI) -> collapsed
    (True), stood (False) or failed (None); and the rows of the runs."""

    verdicts: dict[tuple[str, float, int], dict[float, bool | None]] = field(default_factory=dict)
    rows: dict[tuple[str, float, int, float], dict[str, Any]] = field(default_factory=dict)

    def add(self, key: tuple[str, float, int], level: float, row: Mapping[str, Any], collapsed: bool | None) -> None:
        """Record one run."""
        self.verdicts.setdefault(key, {})[level] = collapsed
        self.rows[(*key, level)] = dict(row)


def _collapsed(row: Mapping[str, Any], fallen_blocks: int, single: bool) -> bool | None:
    """A batch row's verdict (as :func:`rockyade.assess.stripes.collapse_of` decides it): None
    for a run that failed or did not finish."""
    status = row.get("status")
    if status not in ("completed", "overturned"):
        return None
    if single or fallen_blocks == 1:
        return status == "overturned"
    return int(row.get("n_fallen") or 0) >= fallen_blocks


def _stored_row(task: BatchTask) -> dict[str, Any] | None:
    """The summary row a finished run of ``task`` left on disk (completed or overturned, the
    same scene), or None."""
    path = Path(task.out_dir) / "runs" / f"{run_name(task.scene_hash, task.solver.name)}.json"
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    if data.get("scene_hash") != task.scene_hash or data.get("status") not in ("completed", "overturned"):
        return None
    summary = data.get("summary")
    return dict(summary) if isinstance(summary, dict) else None


class Study:
    """A cross-check being run in its working folder (module docstring)."""

    def __init__(
        self,
        plan: CrosscheckPlan,
        stage: Path,
        executor: Executor,
        *,
        progress: bool,
        allow_large: bool,
        say: Callable[[str], None],
    ) -> None:
        self.plan = plan
        self.stage = stage
        self.executor = executor
        self.progress = progress
        self.allow_large = allow_large
        self.say = say
        self.outcomes = Outcomes()
        self.ran = 0
        self.reused = 0
        self.solvers = {(s, f): plan.solver(s, f) for s in plan.solvers for f in plan.dt_factors}
        self.single = len(plan.scene.blocks) == 1

    def folder(self, dt_factor: float) -> Path:
        """Where the runs at ``dt_factor`` go."""
        return self.stage / f"dt{dt_factor:g}"

    def task(self, key: tuple[str, float, int], level: float) -> BatchTask:
        """The batch task of one run."""
        solver, f, i = key
        sp = self.plan.stripes.stripes
        lf = sp.load_factor(i, level)
        m = self.plan.measure
        labels = {
            "record": sp.motions.label(i),
            "record_index": i,
            "dt_factor": f,
            "level_si": level,
            m.column: m.shown(level),
            "load_factor": lf,
        }
        return batch_task(0, self.solvers[(solver, f)], sp.scene_for(i, lf), labels, self.folder(f), save_history=False)

    def pending(self) -> list[tuple[tuple[str, float, int], float, BatchTask]]:
        """The runs of the next round: each search advanced over the runs on disk first."""
        plan, sp = self.plan, self.plan.stripes.stripes
        todo = []
        for key in plan.searches():
            i = key[2]
            verdicts = self.outcomes.verdicts.setdefault(key, {})
            while True:
                levels = next_levels(
                    verdicts,
                    plan.scan_si,
                    plan.resolution,
                    lowest=sp.im_si[i] * 1e-3,
                    highest=sp.im_si[i] * MAX_LOAD_FACTOR,
                )
                levels = [level for level in levels if level not in verdicts]  # a run that failed: the search ends
                missing = []
                for level in levels:
                    task = self.task(key, level)
                    row = _stored_row(task)
                    if row is None:
                        missing.append((key, level, task))
                    else:
                        self.reused += 1
                        self.outcomes.add(key, level, row, _collapsed(row, sp.fallen_blocks, self.single))
                if missing or not levels:
                    todo += missing
                    break
        return todo

    def warm_up(self) -> None:
        """Load, in this process, the compiled code of the solvers that run groups of runs in
        process (``run_group``), on a run of 0.05 s: worker processes forked for each round
        then inherit it rather than load it again (seconds a round on a busy machine)."""
        from rockyade.analysis.metrics import uplift_threshold_rad

        if self.executor.in_process or not self.plan.scene.blocks:
            return
        sp = self.plan.stripes.stripes
        scene = sp.scene_for(0, sp.load_factor(0, self.plan.scan_si[0]))
        scene = replace(scene, duration_s=min(scene.duration_s, 0.05))
        alpha = scene.blocks[0].classical().alpha_rad
        for solver in self.solvers.values():
            key = getattr(solver, "group_key", None)
            if key is None or key(scene) is None:
                continue
            try:
                solver.run_group([scene], uplift_threshold_rad(alpha))  # type: ignore[attr-defined]
            except Exception:  # a warm-up that fails costs only time; the runs say what is wrong
                continue

    def run(self) -> None:
        """Run rounds until every search is done.

        Raises
        ------
        BatchInterruptedError
            Ctrl-C (what finished is on disk).
        """
        rounds = 0
        self.warm_up()
        while True:
            todo = self.pending()
            if not todo:
                return
            rounds += 1
            self.say(f"round {rounds}: {len(todo)} run(s)")
            for f in self.plan.dt_factors:
                part = [(key, level, task) for key, level, task in todo if key[1] == f]
                if not part:
                    continue
                tasks = [_indexed(task, n) for n, (_k, _l, task) in enumerate(part)]
                summary = run_study_tasks(
                    tasks,
                    self.folder(f),
                    executor=self.executor,
                    resume=True,
                    progress=self.progress,
                    desc=f"crosscheck dt x {f:g}, round {rounds}",
                    allow_large=self.allow_large,
                )
                rows = summary.to_dict(orient="records")
                for (key, level, _task), row in zip(part, sorted(rows, key=lambda r: r["index"]), strict=True):
                    self.ran += 1
                    self.outcomes.add(
                        key, level, row, _collapsed(row, self.plan.stripes.stripes.fallen_blocks, self.single)
                    )


def _indexed(task: BatchTask, index: int) -> BatchTask:
    return replace(task, index=index)


# ---------------------------------------------------------------------- the summary


@dataclass(frozen=True)
class Summary:
    """The numbers of a cross-check (complete or partial)."""

    collapse: pd.DataFrame
    pairs: pd.DataFrame
    runs: pd.DataFrame
    fragility: list[dict[str, Any]]
    verdicts: list[str]
    partial: bool


def summarise(plan: CrosscheckPlan, outcomes: Outcomes, partial: bool) -> Summary:
    """Collapse intensities, paired ratios, convergence, verdict agreement and fragility from
    the outcomes (module docstring of :mod:`rockyade.analysis.crosscheck`)."""
    m = plan.measure
    sp = plan.stripes.stripes
    scan = list(plan.scan_si)
    rows = []
    searches: dict[tuple[str, float, int], CollapseSearch] = {}
    for key in plan.searches():
        solver, f, i = key
        found = collapse_summary(outcomes.verdicts.get(key, {}), scan)
        searches[key] = found
        rows.append(
            {
                "record": sp.motions.label(i),
                "record_index": i,
                "solver": solver,
                "dt_factor": f,
                "collapse_intensity": m.shown(found.collapse_intensity),
                "intensity_unit": m.unit,
                "intensity_measure": m.name,
                "bracket_low": m.shown(found.bracket_low),
                "bracket_high": m.shown(found.bracket_high),
                "survived_above_fraction": found.survived_above_fraction,
                "status": found.status,
                "runs": found.runs,
                "failed_runs": found.failed,
            }
        )
    collapse = pd.DataFrame(rows)
    run_rows = []
    for (solver, f, i, level), row in sorted(outcomes.rows.items()):
        run_rows.append(
            {
                "record": sp.motions.label(i),
                "record_index": i,
                "solver": solver,
                "dt_factor": f,
                m.column: m.shown(level),
                "level_si": level,
                "load_factor": level / sp.im_si[i],
                "scan": any(math.isclose(level, s, rel_tol=1e-12) for s in scan),
                "status": row.get("status"),
                "collapsed": outcomes.verdicts[(solver, f, i)].get(level),
                "failure_reason": row.get("failure_reason") or "",
                "run": row.get("run"),
            }
        )
    runs = pd.DataFrame(run_rows)

    def intensities(solver: str, f: float) -> dict[str, float]:
        return {sp.motions.label(i): searches[(solver, f, i)].collapse_intensity for i in plan.records_of(solver)}

    def scan_verdicts(solver: str, f: float) -> dict[tuple[str, float], bool | None]:
        out: dict[tuple[str, float], bool | None] = {}
        for i in plan.records_of(solver):
            v = outcomes.verdicts.get((solver, f, i), {})
            for level in scan:
                if level in v:
                    out[(sp.motions.label(i), level)] = v[level]
        return out

    pair_rows = []
    dt_change: dict[str, float] = {}
    finest = plan.dt_factors[-1]
    for solver in plan.solvers:
        for f in plan.dt_factors[1:]:
            ratio = median_interval(
                paired_ratios(intensities(solver, f), intensities(solver, plan.dt_factors[0])).values()
            )
            same, n = verdict_agreement(scan_verdicts(solver, f), scan_verdicts(solver, plan.dt_factors[0]))
            if f == finest:
                dt_change[solver] = abs(ratio.median - 1.0) if math.isfinite(ratio.median) else math.nan
            pair_rows.append(_pair_row("dt", solver, solver, f, plan.dt_factors[0], ratio, same, n, "", ""))
    verdicts = []
    for f in plan.dt_factors:
        for ia, a in enumerate(plan.solvers):
            for b in plan.solvers[ia + 1 :]:
                ratio = median_interval(paired_ratios(intensities(a, f), intensities(b, f)).values())
                same, n = verdict_agreement(scan_verdicts(a, f), scan_verdicts(b, f))
                v = pair_verdict(a, b, ratio, plan.tolerance, dt_change if len(plan.dt_factors) > 1 else None)
                pair_rows.append(_pair_row("solvers", a, b, f, f, ratio, same, n, v.verdict, v.sentence))
                if f == finest or len(plan.dt_factors) == 1:
                    verdicts.append(f"at dt x {f:g}: {v.sentence}")
    pairs = pd.DataFrame(pair_rows, columns=list(PAIR_COLUMNS))
    fragility = _fragility(plan, runs)
    return Summary(collapse, pairs, runs, fragility, verdicts, partial)


PAIR_COLUMNS = (
    "kind",
    "solver_a",
    "solver_b",
    "dt_factor_a",
    "dt_factor_b",
    "records",
    "median_ratio",
    "ratio_low",
    "ratio_high",
    "same_verdict_runs",
    "compared_runs",
    "same_verdict_share",
    "verdict",
    "sentence",
)


def _pair_row(
    kind: str,
    a: str,
    b: str,
    fa: float,
    fb: float,
    ratio: MedianInterval,
    same: int,
    n: int,
    verdict: str,
    sentence: str,
) -> dict[str, Any]:
    return {
        "kind": kind,
        "solver_a": a,
        "solver_b": b,
        "dt_factor_a": fa,
        "dt_factor_b": fb,
        "records": ratio.n,
        "median_ratio": ratio.median,
        "ratio_low": ratio.low,
        "ratio_high": ratio.high,
        "same_verdict_runs": same,
        "compared_runs": n,
        "same_verdict_share": same / n if n else math.nan,
        "verdict": verdict,
        "sentence": sentence,
    }


def _fragility(plan: CrosscheckPlan, runs: pd.DataFrame) -> list[dict[str, Any]]:
    """Per solver and dt factor, the lognormal fragility of its runs (scan and bisection)
    with its bootstrap intervals (:func:`rockyade.assess.fit.fit_stripes`)."""
    from rockyade.assess.fit import fit_stripes

    m = plan.measure
    out: list[dict[str, Any]] = []
    if runs.empty:
        return out
    for (solver, f), group in runs.groupby(["solver", "dt_factor"], sort=False):
        frame = pd.DataFrame(
            {
                "record_index": group["record_index"],
                m.si_column: group["level_si"],
                "status": np.where(group["collapsed"].isna(), "failed", "completed"),
                "collapsed": group["collapsed"].fillna(False).astype(bool),
            }
        )
        try:
            fit = fit_stripes(frame, m.si_column)
        except (ValueError, np.linalg.LinAlgError) as exc:
            out.append({"solver": solver, "dt_factor": f, "status": f"not fitted: {exc}"})
            continue
        d = fit.to_dict(m.scale, m.unit)
        out.append({"solver": solver, "dt_factor": float(f), **d})
    return out


def _fmt(v: float, digits: int = 4) -> str:
    return f"{v:.{digits}g}" if isinstance(v, (int, float)) and math.isfinite(v) else "-"


def index_text(plan: CrosscheckPlan, summary: Summary, seconds: float) -> str:
    """``index.md``: the verdicts in words and numbers, then how the study was made."""
    m = plan.measure
    sp = plan.stripes.stripes
    lines = [f"# Cross-check of {', '.join(plan.solvers)} on {plan.scene.source or 'the scene'}", ""]
    if summary.partial:
        lines += [
            "**PARTIAL: the study was stopped before every search finished. These numbers are of the runs "
            "that finished; run the same command with --resume to finish it.**",
            "",
        ]
    lines += [
        f"Collapse intensity: the smallest {m.name} ({m.unit}) of each record's scaling at which the scene collapses "
        f"({collapse_rule(plan.scene, sp.fallen_blocks)}), by a scan over {len(plan.scan_si)} levels "
        f"({', '.join(_fmt(m.shown(v), 3) for v in plan.scan_si)} {m.unit}) then bisection to "
        f"{100 * plan.resolution:g} %. Records: {plan.motions.describe()}. Agreement: the median ratio of two "
        f"solvers' collapse intensities, paired by record, within {100 * plan.tolerance:g} % of 1 and its bootstrap "
        f"95 % interval within {200 * plan.tolerance:g} %. Time-step factors: "
        f"{', '.join(f'{f:g}' for f in plan.dt_factors)}.",
        "",
        "## Verdicts",
        "",
    ]
    lines += [f"- {v}" for v in summary.verdicts] or ["- no pair of solvers has collapse intensities to compare"]
    pairs = summary.pairs
    dt_rows = pairs[pairs["kind"] == "dt"] if not pairs.empty else pairs
    if len(dt_rows):
        lines += ["", "## Convergence in the time step", ""]
        for _, r in dt_rows.iterrows():
            lines.append(
                f"- {r.solver_a}: collapse intensity at dt x {r.dt_factor_a:g} / at dt x {r.dt_factor_b:g} = "
                f"{_fmt(r.median_ratio)} (95 % interval {_fmt(r.ratio_low)}-{_fmt(r.ratio_high)}, "
                f"{r.records} records); "
                f"the same verdict in {r.same_verdict_runs} of {r.compared_runs} scan runs"
            )
    lines += [
        "",
        "## Paired ratios",
        "",
        "| a | b | dt factor | records | median a/b | 95 % interval | same verdict | verdict |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for _, r in pairs[pairs["kind"] == "solvers"].iterrows() if not pairs.empty else []:
        lines.append(
            f"| {r.solver_a} | {r.solver_b} | {r.dt_factor_a:g} | {r.records} | {_fmt(r.median_ratio)} | "
            f"{_fmt(r.ratio_low)}-{_fmt(r.ratio_high)} | {r.same_verdict_runs}/{r.compared_runs} | {r.verdict} |"
        )
    lines += [
        "",
        "## Fragility per solver",
        "",
        f"| solver | dt factor | median ({m.unit}) | 90 % interval | beta | 90 % interval |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    key = f"median_{m.unit.replace('/', '_')}"
    for fr in summary.fragility:
        mi = fr.get(f"median_interval_{m.unit.replace('/', '_')}", [math.nan, math.nan])
        bi = fr.get("beta_interval", [math.nan, math.nan])
        lines.append(
            f"| {fr['solver']} | {fr['dt_factor']:g} | {_fmt(fr.get(key, math.nan))} | {_fmt(mi[0])}-{_fmt(mi[1])} | "
            f"{_fmt(fr.get('beta', math.nan), 3)} | {_fmt(bi[0], 3)}-{_fmt(bi[1], 3)} |"
        )
    c = summary.collapse
    if not c.empty:
        open_ = c[c["status"] != BRACKETED]
        above = c["survived_above_fraction"]
        survived = float(np.nanmedian(above)) if above.notna().any() else math.nan
        lines += [
            "",
            "## Searches",
            "",
            f"{len(c) - len(open_)} of {len(c)} searches bracketed a collapse intensity. "
            + (
                f"Not bracketed: {len(open_)} ({', '.join(sorted(set(open_['status'])))}); they are left out of "
                "the ratios."
                if len(open_)
                else ""
            )
            + f" Median fraction of scanned levels above the first collapse that stood: {_fmt(survived, 3)} (above 0: "
            "a stronger scaling of a record stood, the overturning region is not simply connected).",
        ]
    lines += [
        "",
        "## Files",
        "",
        "- `collapse_intensities.csv`: per record, solver and dt factor, the collapse intensity and its bracket;",
        "- `pairs.csv`: per pair of solvers (kind `solvers`) and per solver against itself at a finer step "
        "(kind `dt`), the median ratio, its interval and the share of the same verdict;",
        "- `runs.csv`: every run; `crosscheck.json`: all of it with the plan; `crosscheck.png`: the paired ratios.",
        "",
        f"Runs: {len(summary.runs)}; wall time {seconds:.0f} s.",
    ]
    if not summary.partial:
        lines += ["", "![paired ratios of collapse intensities](crosscheck.png)"]
    return "\n".join(lines) + "\n"


def write_summary(
    plan: CrosscheckPlan, summary: Summary, folder: Path, seconds: float, extra: Mapping[str, Any]
) -> None:
    """The set's files in ``folder`` (the JSON last: it says whether the set is complete)."""
    from rockyade.assess.strict import finite_or_null

    for name, frame in (
        ("collapse_intensities.csv", summary.collapse),
        ("pairs.csv", summary.pairs),
        ("runs.csv", summary.runs),
    ):
        with atomic_open(folder / name) as fh:
            frame.to_csv(fh, index=False, float_format="%.10g", lineterminator="\n")
    if not summary.partial:
        from rockyade.figures.crosscheck import PairedRatios

        PairedRatios.from_pairs(summary.pairs, plan.measure.name, plan.tolerance).save(folder / "crosscheck.png")
    write_text(folder / "index.md", index_text(plan, summary, seconds))
    data = {
        "partial": summary.partial,
        "plan": plan.identity(),
        "scene": plan.scene.source,
        "tolerance": plan.tolerance,
        "collapse_rule": collapse_rule(plan.scene, plan.stripes.stripes.fallen_blocks),
        "levels_source": plan.stripes.levels_source,
        "verdicts": summary.verdicts,
        "pairs": summary.pairs.to_dict(orient="records"),
        "fragility": summary.fragility,
        "collapse_intensities": summary.collapse.to_dict(orient="records"),
        "wall_time_s": seconds,
        **extra,
    }
    write_json(folder / "crosscheck.json", finite_or_null(data))


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
    """Run the study and replace ``out`` with its complete set (module docstring).

    Raises
    ------
    InputError
        ``out`` a swap would destroy, a resume of another study, a run above the cost limits.
    BatchInterruptedError
        Ctrl-C: the partial summary is in ``<out>.partial``; ``--resume`` finishes it.
    """
    out = Path(out)
    check_out(out)
    stage = partial_dir(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    settle(out)
    stage.mkdir(exist_ok=True)
    start = time.perf_counter()
    with output_lock(stage, "--out"):
        identity = plan.identity()
        plan_file = stage / "plan.json"
        stored = _read_json(plan_file)
        if stored is not None and stored != json.loads(json.dumps(identity)) and resume:
            raise InputError(
                "--resume",
                f"the unfinished study in {stage} is another study (its plan.json differs): run without "
                "--resume to start afresh",
            )
        if stored is not None and not resume:
            say(f"discarding the unfinished cross-check in {stage} (--resume would have finished it)")
        if not resume or stored is None:
            for child in stage.iterdir():
                if child.name == DIR_LOCK_NAME:
                    continue
                if child.is_dir() and not child.is_symlink():
                    shutil.rmtree(child)
                else:
                    child.unlink()
            write_json(plan_file, identity)
        study = Study(plan, stage, executor, progress=progress, allow_large=allow_large, say=say)
        try:
            study.run()
        except BatchInterruptedError as exc:
            study.pending()  # what the interrupted round finished, read back from disk
            summary = summarise(plan, study.outcomes, partial=True)
            write_summary(plan, summary, stage, time.perf_counter() - start, {"runs_made": study.ran})
            say(f"partial summary in {stage / 'index.md'}")
            raise BatchInterruptedError(len(summary.runs), exc.unfinished, str(stage / "runs.csv"), exc.hard) from None
        summary = summarise(plan, study.outcomes, partial=False)
        seconds = time.perf_counter() - start
        write_summary(plan, summary, stage, seconds, {"runs_made": study.ran, "runs_reused": study.reused})
        say(f"{study.ran} run(s) made, {study.reused} found done")
        (stage / DIR_LOCK_NAME).unlink(missing_ok=True)  # the lock's file must not go into the set
        _swap(stage, out)
    return summary


def _read_json(path: Path) -> Any:
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return None


__all__ = [
    "DT_FACTORS",
    "RESULT_FILES",
    "CrosscheckPlan",
    "Summary",
    "check_dt_factors",
    "crosscheck_plan",
    "index_text",
    "parse_solvers",
    "partial_dir",
    "run_crosscheck",
    "settle",
    "summarise",
]
