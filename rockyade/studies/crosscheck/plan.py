"""What a cross-check runs (``rockyade crosscheck``, :mod:`rockyade.studies.crosscheck`): the
plan (the scene, the records and their scan of levels shared with ``rockyade fragility``, the
solvers and their time-step factors, the bisection's resolution, the agreement's tolerance),
its checks before anything runs, its expected runs and time, and what its searches found so far
(:class:`Outcomes`)."""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from rockyade.analysis.crosscheck_statistics import RESOLUTION, TOLERANCE, next_levels
from rockyade.assess.fragility_analysis import FragilityPlan, fragility_plan
from rockyade.assess.measures import Measure
from rockyade.assess.motions import MotionSet
from rockyade.assess.stripes import MAX_LOAD_FACTOR
from rockyade.batch import MAX_RUNS
from rockyade.constants import CODE_GRAVITY, G
from rockyade.errors import InputError
from rockyade.runner import Executor
from rockyade.runner.cost_limits import check_cost, check_study_time
from rockyade.runner.rows import Cell, Cells, RunRow
from rockyade.scene import Scene
from rockyade.solvers import solver_class, solver_names
from rockyade.solvers.base import DT_FACTOR_MIN, Solver, SolverBase, check_scene

#: Time-step factors by default: the solver's own step, and half of it (convergence).
DT_FACTORS = (1.0, 0.5)
#: Start-up costs the solvers' per-run estimates leave out, measured on a quiet 2-core machine
#: (docs/verification.md, "Cost"): per round and time-step factor, a pool of worker processes
#: forked and the round's runs and summary written, s;
ROUND_OVERHEAD_S = 1.0
#: loading the in-process solvers' compiled kernels once before the rounds, s;
WARM_UP_S = 2.0
#: compiling them when numba's cache lacks them (the first run after an install or a change of
#: the kernels), CPU s.
COMPILE_S = 60.0
#: The option of ``rockyade crosscheck`` each key of a plan's identity stands for (a refused
#: resume names it).
OPTION_NAMES = {
    "scene_hash": "the scene",
    "motions": "--records/--suite",
    "measure": "--intensity",
    "scan_si": "--levels",
    "solvers": "--solvers",
    "dt_factors": "--dt-factors",
    "resolution": "--resolution",
    "records_per_solver": "records_per_solver",
    "solver_options": "--yade-timeout",
    "fallen_blocks": "--fallen-blocks",
    "sample_dt_s": "--sample-dt",
    "tail_s": "--tail",
}


def option_name(key: str) -> str:
    """The option a key of a plan's identity (``motions.count``, say) stands for."""
    return OPTION_NAMES.get(key.split(".")[0], key)


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
    solver_options: Mapping[str, Cell] = field(default_factory=dict)

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

    def next_levels(self, record: int, verdicts: Mapping[float, bool | None]) -> list[float]:
        """The levels (SI) a search of ``record`` runs next after ``verdicts`` (level -> collapsed,
        stood or failed): the scan, its extensions within the record's load-factor limits, then
        bisection (:func:`rockyade.analysis.crosscheck_statistics.next_levels`); none when it is done."""
        im = self.stripes.stripes.im_si[record]
        return next_levels(
            dict(verdicts), self.scan_si, self.resolution, lowest=im * 1e-3, highest=im * MAX_LOAD_FACTOR
        )

    def searches(self) -> list[tuple[str, float, int]]:
        """Every (solver, dt factor, record index) searched."""
        return [(s, f, i) for f in self.dt_factors for s in self.solvers for i in self.records_of(s)]

    def identity(self) -> dict[str, object]:
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

    def compiling(self) -> bool:
        """Some solver's compiled code is not in numba's cache: the first run compiles it (each
        solver says, :meth:`rockyade.solvers.base.SolverBase.compiled_cached`)."""
        solvers = [self.solver(s, 1.0) for s in self.solvers]
        return any(isinstance(s, SolverBase) and not s.compiled_cached(self.scene) for s in solvers)

    def startup_s(self) -> float:
        """What the solvers' estimates leave out, s: each round's pool of workers, the warm-up
        of the in-process kernels and, when numba's cache lacks them, their compilation."""
        in_process = any(solver_class(s).IN_PROCESS for s in self.solvers)
        seconds = self.rounds() * ROUND_OVERHEAD_S
        if in_process:
            seconds += COMPILE_S if self.compiling() else WARM_UP_S
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
        compiling = self.compiling()
        return (
            f"cost: about {self.expected_runs()} runs ({len(self.searches())} searches of {per_search:.0f} runs: "
            f"{len(self.scan_si)} scan levels, then bisection to {100 * self.resolution:g} %), "
            f"about {_duration(seconds / max(1, workers) + startup)} on {workers} worker(s): the solvers' estimates "
            f"({_duration(seconds / max(1, workers))}) and start-up ({_duration(startup)}: {self.rounds()} rounds"
            + (", the kernels compiled once: numba's cache lacks them" if compiling else "")
            + "), on an idle machine"
        )


def _solver(name: str, dt_factor: float, solver_options: Mapping[str, Cell]) -> Solver:
    """Solver ``name`` at ``dt_factor`` (an option only when not 1) with the options it takes."""
    options: dict[str, object] = {k: v for k, v in solver_options.items() if k in solver_class(name).OPTIONS}
    if dt_factor != 1.0:
        options["dt_factor"] = dt_factor
    return solver_class(name).from_options(options)


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
    solver_options: Mapping[str, Cell] | None = None,
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


@dataclass
class Outcomes:
    """Every run's verdict so far: (solver, dt factor, record index) -> level (SI) -> collapsed
    (True), stood (False) or failed (None); and the rows of the runs."""

    verdicts: dict[tuple[str, float, int], dict[float, bool | None]] = field(default_factory=dict)
    rows: dict[tuple[str, float, int, float], Cells] = field(default_factory=dict)

    def add(self, key: tuple[str, float, int], level: float, row: Mapping[str, Cell], collapsed: bool | None) -> None:
        """Record one run: its row (:meth:`rockyade.runner.rows.RunRow.summary`) and its verdict
        (:attr:`rockyade.runner.rows.RunRow.collapsed`)."""
        self.verdicts.setdefault(key, {})[level] = collapsed
        self.rows[(*key, level)] = dict(row)

    def add_run(self, key: tuple[str, float, int], level: float, row: RunRow) -> None:
        """Record one run from its row."""
        self.add(key, level, row.summary(), row.collapsed)


__all__ = [
    "DT_FACTORS",
    "OPTION_NAMES",
    "CrosscheckPlan",
    "Outcomes",
    "check_dt_factors",
    "classical_static",
    "crosscheck_plan",
    "option_name",
    "parse_solvers",
]
