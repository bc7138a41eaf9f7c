"""``rockyade crosscheck``: several solvers on one scene over a record set, compared by their
collapse intensities (the statistics: :mod:`rockyade.analysis.crosscheck_statistics`; the method and
what was measured: docs/verification.md).

For each solver, each time-step factor (1, and 0.5 for the convergence check) and each
record, a collapse search: the scan's levels (from the scene's static collapse acceleration,
as ``rockyade fragility`` chooses its stripes, :func:`rockyade.assess.fragility_analysis.fragility_plan`;
for a single block tan(alpha) g with the scene's classical alpha, :func:`classical_static`),
then bisection to the resolution. The searches advance together, one round at a time; each
round's runs go through the batch machinery (:func:`rockyade.batch.run_study_tasks`:
the runner's executors, grouped runs, a JSON per finished run written as it ends, Ctrl-C).

Files. ``--out`` holds the complete set (``collapse_intensities.csv``, ``pairs.csv``,
``runs.csv``, ``crosscheck.png``, ``index.md`` and ``crosscheck.json``, the file that marks it
complete) and, while a study is unfinished, its journal ``<out>/partial/``
(:class:`rockyade.runner.journal.Journal`, as every study command has it): ``study.json`` (what
the study is), ``dt<f>/runs/`` (one JSON per finished run, by scene hash and solver, one
folder per time-step factor) and, after Ctrl-C, a summary marked PARTIAL. When every search
is done the summary is written as a new set that replaces the old one as a whole
(:mod:`rockyade.io.resultset`): an error, Ctrl-C or a kill leaves the previous complete set,
or the new one, never a mix; then the journal goes.

Resume. Every search is a function of its outcomes, so ``--resume`` replays the searches
from the journal's runs and runs only what is missing (a run that failed is run again); after
Ctrl-C or kill -9 no finished run is repeated. Without ``--resume`` an unfinished study's
journal is discarded and the study starts afresh; with it, a study whose identity differs is
refused.
"""

from __future__ import annotations

import itertools
import json
import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from rockyade.analysis.crosscheck_statistics import (
    RESOLUTION,
    TOLERANCE,
    next_levels,
)
from rockyade.assess.fragility_analysis import FragilityPlan, fragility_plan
from rockyade.assess.measures import Measure
from rockyade.assess.motions import MotionSet
from rockyade.assess.stripes import MAX_LOAD_FACTOR
from rockyade.batch import MAX_RUNS, BatchTask, batch_task, run_name, run_study_tasks
from rockyade.constants import CODE_GRAVITY, G
from rockyade.errors import BatchInterruptedError, InputError
from rockyade.io.folders import output_folder
from rockyade.io.locking import output_lock
from rockyade.io.resultset import replacing_set, settle
from rockyade.runner import Executor
from rockyade.runner.cost_limits import check_cost, check_study_time
from rockyade.runner.journal import IDENTITY_FILE, Journal, read_run
from rockyade.scene import Scene
from rockyade.solvers import make_solver, solver_class, solver_names
from rockyade.solvers.base import DT_FACTOR_MIN, Solver, check_scene
from rockyade.studies.crosscheck_report import Summary, summarise, write_summary

#: Time-step factors by default: the solver's own step, and half of it (convergence).
DT_FACTORS = (1.0, 0.5)
#: The files of a complete set.
RESULT_FILES = ("collapse_intensities.csv", "pairs.csv", "runs.csv", "crosscheck.json", "crosscheck.png", "index.md")
#: Start-up costs the solvers' per-run estimates leave out, measured on a quiet 2-core machine
#: (docs/verification.md, "Cost"): per round and time-step factor, a pool of worker processes
#: forked and the round's runs and summary written, s;
ROUND_OVERHEAD_S = 1.0
#: loading the in-process solvers' compiled kernels once before the rounds, s;
WARM_UP_S = 2.0
#: compiling them when numba's cache lacks them (the first run after an install or a change of
#: the kernels), CPU s.
COMPILE_S = 60.0
#: The file that marks a set complete (written last).
RESULT_LAST = "crosscheck.json"
#: The journal's folder in --out while a study is unfinished.
PARTIAL_DIR = "partial"


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

    def rounds(self) -> int:
        """Rounds the study is expected to take: the scan, then one per bisection step, per
        time-step factor (the searches of one factor advance together)."""
        per_search = self.expected_runs() / max(1, len(self.searches()))
        return len(self.dt_factors) * (1 + max(0, round(per_search) - len(self.scan_si)))

    def startup_s(self) -> float:
        """What the solvers' estimates leave out, s: each round's pool of workers, the warm-up
        of the in-process kernels and, when numba's cache lacks them, their compilation."""
        in_process = any(solver_class(s).IN_PROCESS for s in self.solvers)
        seconds = self.rounds() * ROUND_OVERHEAD_S
        if in_process:
            seconds += WARM_UP_S if kernels_cached(len(self.scene.blocks) == 1) else COMPILE_S
        return seconds

    def heaviest_scene(self) -> Scene:
        """The run the study's estimates take for every run: the longest record at the top level."""
        plan = self.stripes.stripes
        longest = int(np.argmax(plan.durations_s))
        return plan.scene_for(longest, plan.load_factor(longest, max(self.scan_si)))

    def run_seconds(self) -> float:
        """The solvers' estimates summed over the expected runs, s (one worker, no start-up)."""
        scene = self.heaviest_scene()
        per_search = self.expected_runs() / max(1, len(self.searches()))
        seconds = 0.0
        for s, f, _i in self.searches():
            seconds += self.solver(s, f).estimate_cost(scene).wall_time_s * per_search
        return seconds

    def expected_seconds(self, workers: int) -> float:
        """The study's expected wall time on ``workers`` workers of an idle machine, s."""
        return self.run_seconds() / max(1, workers) + self.startup_s()

    def check(self, workers: int, allow_large: bool = False) -> None:
        """Before anything runs: each solver checks the scene (:meth:`SolverBase.check_scene`:
        what its runs would refuse, e.g. a mu Siconos cannot reach) and the heaviest run's cost
        (:func:`rockyade.runner.cost_limits.check_cost`), and the study's expected time is held to
        :data:`rockyade.runner.cost_limits.MAX_STUDY_S` (``allow_large`` lifts the cost limits).

        Raises
        ------
        InputError
            A solver refusing the scene (its own field, the solver named), a run or the study
            above the cost limits.
        """
        scene = self.heaviest_scene()
        for name in self.solvers:
            try:
                check_scene(self.solver(name, 1.0), self.scene)
            except InputError as exc:
                if name in exc.message:
                    raise
                raise InputError(exc.field, f"the {name} solver refuses the scene: {exc.message}", exc.source) from None
            for f in self.dt_factors:
                check_cost(scene, self.solver(name, f), allow_large, label=f"{name} at dt x {f:g}")
        if not allow_large:
            check_study_time(self.expected_seconds(workers), "the cross-check", workers)

    def cost_line(self, workers: int) -> str:
        """The study's expected runs and time, before anything runs."""
        per_search = self.expected_runs() / max(1, len(self.searches()))
        seconds = self.run_seconds()
        startup = self.startup_s()
        compiling = any(solver_class(s).IN_PROCESS for s in self.solvers) and not kernels_cached(
            len(self.scene.blocks) == 1
        )
        return (
            f"cost: about {self.expected_runs()} runs ({len(self.searches())} searches of {per_search:.0f} runs: "
            f"{len(self.scan_si)} scan levels, then bisection to {100 * self.resolution:g} %), "
            f"about {_duration(seconds / max(1, workers) + startup)} on {workers} worker(s): the solvers' estimates "
            f"({_duration(seconds / max(1, workers))}) and start-up ({_duration(startup)}: {self.rounds()} rounds"
            + (", the kernels compiled once: numba's cache lacks them" if compiling else "")
            + "), on an idle machine"
        )


def kernels_cached(single: bool = True) -> bool:
    """Whether numba's on-disk cache holds the in-process solvers' batch kernels (Housner's
    integrator; the reference DEM's grouped and single-body kernels for one block, ``single``,
    its general kernel for several): else the first run compiles them."""
    from rockyade.housner.integrator import _integrate
    from rockyade.kernel.runs import simulate_runs
    from rockyade.kernel.simulation import simulate
    from rockyade.kernel.single import simulate_single

    for dispatcher in (simulate_runs, simulate_single, _integrate) if single else (simulate,):
        try:  # numba's index of the function's cache: empty when missing or of other source (stale)
            cache: Any = getattr(dispatcher, "_cache", None)
            if not cache._cache_file._load_index():
                return False
        except Exception:  # numba's internals moved: assume the cache is there (the smaller estimate)
            return True
    return True


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
    """Distinct factors in [DT_FACTOR_MIN, 1] (every solver's ``dt_factor`` range,
    :func:`rockyade.solvers.base.check_dt_factor`), the first 1 (the solvers' own steps)."""
    out = tuple(float(v) for v in values)
    if not out or out[0] != 1.0 or len(set(out)) != len(out) or any(not (DT_FACTOR_MIN <= v <= 1.0) for v in out):
        raise InputError(
            field_name,
            f"must be distinct factors in [{DT_FACTOR_MIN:g}, 1] on the solvers' time steps, the first 1, "
            f"got {values!r}",
        )
    return out


def classical_static(scene: Scene) -> tuple[float, str] | None:
    """A single block's static collapse acceleration from the scene's classical alpha, tan(alpha) g
    (m/s^2, Housner 1963: a block rocks, and a static load tips it, above it), and its words;
    None for an assembly (or a block with loads), whose alpha0 is the limit analysis'.

    The classical alpha is what the solvers run (``scene.blocks[0].classical()``, as
    ``rockyade params`` shows it): a declared ``alpha_rad`` (specimen 1: 0.235 rad) rather than
    the nominal geometry's atan(b / h) (0.245 rad) that the limit analysis takes.
    """
    if len(scene.blocks) != 1 or scene.loads:
        return None
    alpha = scene.blocks[0].classical().alpha_rad
    value = math.tan(alpha) * G
    return value, (
        f"tan(alpha) g = {value:.4g} m/s^2 (the scene's classical alpha = {alpha:.4g} rad, as the solvers run it, "
        f"x the mechanics' g = {G:g} m/s^2; {value / CODE_GRAVITY:.4g} g in standard gravity)"
    )


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
    workers: int = 2,
) -> CrosscheckPlan:
    """Check the inputs, measure the records and choose the scan; nothing runs yet.

    Parameters
    ----------
    scene, motions, measure
        As :func:`rockyade.assess.fragility_analysis.fragility_plan` takes them.
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
        Go beyond :data:`rockyade.batch.study.MAX_RUNS` expected runs, the cost limits of one
        run and :data:`rockyade.runner.cost_limits.MAX_STUDY_S` of expected time.
    workers
        The workers that will run it (the expected time is over them).

    Raises
    ------
    InputError
        A bad option (named), a solver that cannot change its time step, a record that
        cannot be scaled to the levels, a solver that refuses the scene
        (:meth:`CrosscheckPlan.check`), a study above the run, cost or time limits.
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
        static_override=classical_static(scene),
        levels=levels,
        extend=False,
        executor=executor,
        fallen_blocks=fallen_blocks,
        sample_dt_s=sample_dt_s,
        tail_s=tail_s,
        progress=progress,
    )
    plan = CrosscheckPlan(stripes, names, factors, resolution, tolerance, dict(records_per_solver or {}), options)
    plan.check(workers, allow_large)
    expected = plan.expected_runs()
    if expected > MAX_RUNS and not allow_large:
        raise InputError(
            "--allow-large",
            f"the cross-check is expected to make {expected:,} runs, more than the limit of {MAX_RUNS:,}: fewer "
            "records, solvers or levels, or pass --allow-large",
        )
    return plan


# ---------------------------------------------------------------------- the folders


def journal_dir(out: Path) -> Path:
    """The journal of an unfinished cross-check writing ``out`` (its runs, its identity and,
    after Ctrl-C, the partial summary)."""
    return out / PARTIAL_DIR


def _complete(folder: Path) -> bool:
    """The folder holds a complete cross-check set (its JSON says so)."""
    try:
        data = json.loads((folder / RESULT_LAST).read_text())
    except (OSError, ValueError):
        return False
    return isinstance(data, dict) and data.get("partial") is False


def check_out(out: Path) -> None:
    """Refuse an ``--out`` that is a link or a file, or whose journal folder is a link
    (InputError naming ``--out``)."""
    for path in (out, journal_dir(out)):
        if path.is_symlink():
            raise InputError("--out", f"{path} is a symbolic link; give a real folder")
        if path.exists() and not path.is_dir():
            raise InputError("--out", f"{path} is a file; give a folder")


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
        return batch_task(0, self.solvers[(solver, f)], sp.scene_for(i, lf), labels, save_history=False)

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
                    row = read_run(
                        self.folder(key[1]) / "runs", run_name(task.scene_hash, task.solver.name), task.scene_hash
                    )
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
        """Load (or, on a cold numba cache, compile) in this process the compiled code of the
        solvers that run in process, as the batch runs them (the lean solver of
        :func:`rockyade.batch.batch_task`: without energy terms), on a run of 0.05 s: both
        the grouped path (``run_group``) and the run of its own. The worker processes forked for
        each round inherit it. Before, the warm-up used the plan's solvers, whose energy terms
        keep the reference DEM out of groups: every worker of every round loaded the kernels
        again and, on a cold cache, both workers compiled the same kernels at once (minutes of
        CPU under load; docs/verification.md, "Cost")."""
        from rockyade.analysis.metrics import uplift_threshold_rad

        if self.executor.in_process or not self.plan.scene.blocks:
            return
        level = self.plan.scan_si[0]
        for (name, f), solver in self.solvers.items():
            if not getattr(solver, "IN_PROCESS", False):
                continue
            task = self.task((name, f, 0), level)
            scene = replace(task.scene, duration_s=min(task.scene.duration_s, 0.05))
            lean = task.solver
            try:
                key = getattr(lean, "group_key", None)
                if key is not None and key(scene) is not None:
                    alpha = scene.blocks[0].classical().alpha_rad
                    lean.run_group([scene], uplift_threshold_rad(alpha))  # type: ignore[attr-defined]
                lean.run(scene)
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
        ``out`` a link or a file, a resume of another study or of nothing, a run above the
        cost limits, another process writing ``out``.
    BatchInterruptedError
        Ctrl-C: the partial summary is in ``<out>/partial``; ``--resume`` finishes it.
    """
    out = Path(out)
    check_out(out)
    start = time.perf_counter()
    with output_folder(out), output_lock(out, "--out"):
        settle(out, RESULT_FILES, RESULT_LAST)
        unfinished = (journal_dir(out) / IDENTITY_FILE).is_file()
        if resume and not unfinished and _complete(out):
            raise InputError(
                "--resume",
                f"{out} is a complete cross-check and nothing is unfinished: there is nothing to resume "
                "(run without --resume to run the study again)",
            )
        if unfinished and not resume:
            say(f"discarding the unfinished cross-check in {journal_dir(out)} (--resume would have finished it)")
        journal = Journal(journal_dir(out), plan.identity(), resume)
        study = Study(plan, journal.folder, executor, progress=progress, allow_large=allow_large, say=say)
        try:
            study.run()
        except BatchInterruptedError as exc:
            study.pending()  # what the interrupted round finished, read back from disk
            summary = summarise(plan, study.outcomes, partial=True)
            write_summary(plan, summary, journal.folder, time.perf_counter() - start, {"runs_made": study.ran})
            say(f"partial summary in {journal.folder / 'index.md'}")
            raise BatchInterruptedError(
                len(summary.runs),
                exc.unfinished,
                str(journal.folder / "runs.csv"),
                exc.hard,
                "--resume",
                listed="the finished runs (the searches' later runs are chosen from them when resumed)",
                unfinished_what="of the interrupted round unfinished",
            ) from None
        summary = summarise(plan, study.outcomes, partial=False)
        seconds = time.perf_counter() - start
        with replacing_set(out, RESULT_FILES, RESULT_LAST) as stage:
            write_summary(plan, summary, stage, seconds, {"runs_made": study.ran, "runs_reused": study.reused})
        journal.clear()
        say(f"{study.ran} run(s) made, {study.reused} found done")
    return summary


__all__ = [
    "DT_FACTORS",
    "RESULT_FILES",
    "CrosscheckPlan",
    "Summary",
    "check_dt_factors",
    "crosscheck_plan",
    "journal_dir",
    "parse_solvers",
    "run_crosscheck",
    "summarise",
]
