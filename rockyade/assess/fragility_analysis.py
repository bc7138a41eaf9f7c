"""Collapse fragility of any scene: records scaled to stripes of an intensity measure, runs
through the runner, the lognormal fit and its band.

::

    from rockyade.assess import fragility_plan, run_fragility, parse_measure, ec8_suite

    plan = fragility_plan(scene, ec8_suite(1, "B", 0.25 * 9.80665), parse_measure("pga"), "housner")
    result = run_fragility(plan)                 # stripes, runs, fit
    result.fit.fragility.median / 9.80665        # median PGA, g (standard gravity)

The stripes (:mod:`rockyade.assess.stripes`): every record scaled, by a load factor on its
accelerations as read, to each level. Default levels, when none are given: the static
collapse acceleration of the scene, alpha0 g (:func:`rockyade.limit.limit_analysis`: below
it rigid blocks held by their joints do not move at all, so nothing collapses), times 1,
sqrt 2, 2, ..., 8 in PGA (7 levels); in another measure the same levels times the records'
median ratio of that measure to their PGA. Default levels are then extended, one level a
round, up (times sqrt 2) while fewer than half the records collapse at the top level, and
down while more than half collapse at the bottom one, at most :data:`MAX_EXTRA_LEVELS`
rounds: the median is then inside the tested range.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from rockyade.assess.measures import Measure
from rockyade.assess.motions import MotionSet
from rockyade.assess.stripe_fit import StripeFit, fit_stripes, stripe_table
from rockyade.assess.stripes import (
    DEFAULT_SAMPLE_DT_S,
    DEFAULT_TAIL_S,
    StripePlan,
    StripesInterruptedError,
    check_fallen_blocks,
    collapse_rule,
    record_measures,
    run_stripes,
    runs_frame,
)
from rockyade.constants import CODE_GRAVITY, G
from rockyade.errors import InputError, RockyadeError
from rockyade.io.strict_json import finite_or_null
from rockyade.runner import Executor
from rockyade.runner.study_folder import StudyFolder
from rockyade.scene import Scene
from rockyade.solvers import as_solver
from rockyade.solvers.base import Solver, check_scene
from rockyade.solvers.cost_estimate import duration_text

if TYPE_CHECKING:
    from rockyade.runner.stopping import StopRequest

#: Default levels as multiples of the static collapse acceleration (module docstring).
DEFAULT_FACTORS = tuple(float(2.0 ** (k / 2.0)) for k in range(7))
#: Ratio between successive levels when extending, and the most extra rounds.
EXTEND_RATIO = math.sqrt(2.0)
MAX_EXTRA_LEVELS = 4
#: Levels per analysis, at most.
MAX_LEVELS = 50
#: Levels without a static collapse acceleration (a scene with no mechanism): PGA, g.
FALLBACK_PGA_G = (0.05, 0.1, 0.2, 0.4, 0.8)


def default_solver(scene: Scene) -> str:
    """Housner for a single block, the reference DEM otherwise."""
    return "housner" if len(scene.blocks) == 1 else "reference"


@dataclass(frozen=True)
class FragilityPlan:
    """What a fragility analysis will run (see :func:`fragility_plan`).

    Attributes
    ----------
    stripes
        The runs' shared settings.
    records
        Per record: ``record``, ``duration_s``, ``pga_m_s2`` and ``im_si`` at load factor 1.
    levels_si
        The first round's levels, SI.
    levels_source
        How they were chosen.
    extend
        Extend the levels (module docstring).
    static_acceleration_m_s2
        alpha0 g of the scene (NaN when not computed).
    """

    stripes: StripePlan
    records: pd.DataFrame
    levels_si: tuple[float, ...]
    levels_source: str
    extend: bool
    static_acceleration_m_s2: float = math.nan
    notes: tuple[str, ...] = ()

    @property
    def measure(self) -> Measure:
        """The intensity measure."""
        return self.stripes.measure

    @property
    def runs_planned(self) -> int:
        """Runs of the first round."""
        return len(self.levels_si) * self.stripes.motions.count

    def cost_line(self, workers: int) -> str:
        """The cost of the first round: the longest record's run estimate, times the runs,
        over the workers (and the solver's compilation, when numba's cache lacks it)."""
        plan = self.stripes
        longest = int(np.argmax(plan.durations_s))
        top = max(self.levels_si)
        estimate = plan.solver.estimate_cost(plan.scene_for(longest, plan.load_factor(longest, top)))
        total = estimate.wall_time_s * self.runs_planned / max(workers, 1) + estimate.compile_s
        return (
            f"cost: {self.runs_planned} runs of {plan.solver.name}, each at most {estimate.describe()}; "
            f"about {duration_text(total)} on {workers} worker(s)"
        )


def static_acceleration(scene: Scene) -> tuple[float, str]:
    """(alpha0 g in m/s^2, what it is), the smaller of the two directions; NaN without a
    mechanism. A scene that cannot stand raises :class:`SceneCannotStandError`."""
    from rockyade.limit import limit_analysis

    values = []
    for direction in ("+x", "-x"):
        result = limit_analysis(scene, direction=direction, nonlinear=False)
        if result.status == "unstable":
            raise SceneCannotStandError(scene.source)
        if result.status == "collapse":
            assert result.load_multiplier is not None  # a collapse carries its multiplier (limit.lp)
            values.append(float(result.load_multiplier) * result.model.g)
    if not values:
        return math.nan, "no mechanism in either direction"
    return min(values), (
        f"alpha0 g = {min(values):.4g} m/s^2 (alpha0 x the mechanics' g = {G:g} m/s^2; "
        f"{min(values) / CODE_GRAVITY:.4g} g in standard gravity), limit analysis"
    )


class SceneCannotStandError(RockyadeError):
    """The scene cannot stand under gravity: no fragility and no check (the command exits 1)."""

    def __init__(self, source: str | None) -> None:
        where = f"{source}: " if source else ""
        super().__init__(
            f"{where}the scene cannot stand under gravity: no equilibrium with no-tension joints exists "
            "(rockyade limit says 'unstable'), so it has no collapse intensity and no code check"
        )


class ZeroCapacityError(RockyadeError):
    """The scene moves under any horizontal acceleration (the limit analysis' lambda is 0): the
    default levels, multiples of it, would all be 0 (the command exits 1)."""

    def __init__(self, static_text: str) -> None:
        super().__init__(
            f"the scene has no lateral capacity: the limit analysis collapses it at lambda = 0 ({static_text}; a "
            "joint without friction slides under any horizontal acceleration), so the default levels, multiples "
            "of it, would all be 0 g: give a friction angle > 0, or your own --levels"
        )


def check_levels(levels: Sequence[float], measure: Measure) -> tuple[float, ...]:
    """Levels in the measure's shown unit (g or m/s), each > 0, at least 2, at most
    :data:`MAX_LEVELS`; returned in SI, sorted and distinct."""
    values = sorted({float(v) for v in levels})
    if len(values) < 2 or len(values) > MAX_LEVELS:
        raise InputError("--levels", f"needs 2 to {MAX_LEVELS} distinct levels, got {len(values)}")
    bad = [v for v in values if not (math.isfinite(v) and v > 0)]
    if bad:
        raise InputError("--levels", f"must all be > 0 {measure.unit}, got {bad[0]:g}")
    return tuple(v * measure.scale for v in values)


def fragility_plan(
    scene: Scene,
    motions: MotionSet,
    measure: Measure,
    solver: Solver | str | None = None,
    *,
    levels: Sequence[float] | None = None,
    extend: bool | None = None,
    executor: Executor | None = None,
    fallen_blocks: int = 1,
    sample_dt_s: float = DEFAULT_SAMPLE_DT_S,
    tail_s: float = DEFAULT_TAIL_S,
    progress: bool = True,
    static_override: tuple[float, str] | None = None,
) -> FragilityPlan:
    """Read (or generate) the records, measure them and choose the levels; nothing runs yet.

    Parameters
    ----------
    scene
        Any scene (its motion is replaced).
    motions
        The records (:mod:`rockyade.assess.motions`).
    measure
        The intensity measure (``pga``, ``pgv``, ``sa(T)``).
    solver
        A Solver or a name (default: :func:`default_solver`).
    levels
        Levels in the measure's shown unit (g, or m/s for PGV); default: the module
        docstring's, extended.
    extend
        Extend the levels (default: with default levels only).
    executor
        Where records are generated (default: 2 local processes).
    fallen_blocks
        Fallen blocks that make a collapse (several blocks).
    sample_dt_s, tail_s
        Output sampling and free motion after each record, s.
    static_override
        The static collapse acceleration (m/s^2) and its words, in place of the limit
        analysis' (:func:`static_acceleration`, still run: a scene that cannot stand stops);
        ``rockyade crosscheck`` gives a single block's classical one.
    """
    executor = executor or Executor("local", 2)
    solver = as_solver(solver or default_solver(scene))
    check_scene(solver, scene)  # what every run would refuse (housner on a stack), before any run
    fallen_blocks = check_fallen_blocks(scene, fallen_blocks)
    if not (math.isfinite(sample_dt_s) and 1e-4 <= sample_dt_s <= 0.1):
        raise InputError("--sample-dt", f"must be in [0.0001, 0.1] s, got {sample_dt_s!r}")
    if not (math.isfinite(tail_s) and 0.0 <= tail_s <= 60.0):
        raise InputError("--tail", f"must be in [0, 60] s, got {tail_s!r}")
    if measure.kind == "ag":
        raise InputError("--intensity", "ag is the site's: use rockyade assess")
    given = check_levels(levels, measure) if levels is not None else None
    static_found = static_acceleration(scene)  # also: a scene that cannot stand stops here
    static, static_text = static_override if static_override is not None else static_found
    if given is None and static <= 0.0:
        raise ZeroCapacityError(static_text)  # before any record is read or generated
    records = record_measures(motions, measure, executor, progress)
    records.insert(0, "record", [motions.label(i) for i in range(motions.count)])
    notes = []
    if given is not None:
        chosen, source = given, "given"
    else:
        chosen, source = _default_levels(measure, records, static, static_text)
        if math.isnan(static):
            notes.append(f"the scene has no static mechanism: levels from PGA {FALLBACK_PGA_G} g")
    plan = StripePlan(
        scene,
        motions,
        measure,
        tuple(float(v) for v in records["im_si"]),
        tuple(float(v) for v in records["duration_s"]),
        solver,
        fallen_blocks,
        sample_dt_s,
        tail_s,
    )
    for level in chosen:  # every load factor in range before anything runs
        for i in range(motions.count):
            plan.load_factor(i, level)
    return FragilityPlan(
        plan,
        records,
        chosen,
        source,
        given is None if extend is None else bool(extend),
        static,
        tuple(notes),
    )


def _default_levels(
    measure: Measure, records: pd.DataFrame, static: float, static_text: str
) -> tuple[tuple[float, ...], str]:
    """Levels from the static collapse acceleration (module docstring), SI."""
    if static <= 0.0:
        raise ZeroCapacityError(static_text)
    if math.isnan(static):
        pga_levels = np.array(FALLBACK_PGA_G) * CODE_GRAVITY
        text = "PGA levels of the fallback (no static mechanism)"
    else:
        pga_levels = static * np.array(DEFAULT_FACTORS)
        text = f"{static_text} x {', '.join(f'{f:.3g}' for f in DEFAULT_FACTORS)} in PGA"
    if measure.kind == "pga":
        return tuple(float(v) for v in pga_levels), text
    ratio = float(np.median(records["im_si"] / records["pga_m_s2"]))
    return (
        tuple(float(v) for v in pga_levels * ratio),
        f"{text}, times the records' median {measure.name} / PGA = {ratio:.4g}"
        + (" s" if measure.kind == "pgv" else ""),
    )


@dataclass
class FragilityResult:
    """A fragility analysis: its plan, runs, stripes and fit.

    Attributes
    ----------
    plan
        What was planned.
    runs
        One row per run (:func:`rockyade.assess.stripes.runs_frame`).
    stripes
        Per level (:func:`rockyade.assess.stripe_fit.stripe_table`), the level in SI and shown.
    fit
        The lognormal fit and its band.
    levels_added
        Levels added by the extension, SI.
    """

    plan: FragilityPlan
    runs: pd.DataFrame
    stripes: pd.DataFrame
    fit: StripeFit
    levels_added: list[float] = field(default_factory=list)

    @property
    def measure(self) -> Measure:
        """The intensity measure."""
        return self.plan.measure

    @property
    def failed(self) -> int:
        """Runs that failed."""
        return int((self.runs["status"] == "failed").sum())

    def fraction_at(self, level_si: float) -> dict[str, float]:
        """Collapses, runs, fraction and its 95 % Wilson interval at a level tested."""
        si = self.measure.si_column
        row = self.stripes[np.isclose(self.stripes[si], level_si, rtol=1e-9, atol=0)]
        if row.empty:
            raise KeyError(level_si)
        r = row.iloc[0]
        return {
            "n_collapse": int(r.n_collapse),
            "n_runs": int(r.n_runs),
            "fraction": float(r.fraction),
            "fraction_lo": float(r.fraction_lo),
            "fraction_hi": float(r.fraction_hi),
        }

    def to_dict(self) -> dict[str, object]:
        """JSON-ready (strict: a number that does not exist is null): the fit, the stripes, the
        records, how the levels were chosen."""
        m, plan = self.measure, self.plan
        return finite_or_null(
            {
                "scene": plan.stripes.scene.source,
                "measure": m.to_dict(),
                "solver": plan.stripes.solver.name,
                "collapse_rule": collapse_rule(plan.stripes.scene, plan.stripes.fallen_blocks),
                "motions": plan.stripes.motions.to_dict(),
                "load_factor": "multiplies each record's accelerations as read (after the conversion of the file's "
                "units to m/s^2)",
                "levels_source": plan.levels_source,
                "levels_added": [v / m.scale for v in self.levels_added],
                "static_acceleration_m_s2": plan.static_acceleration_m_s2,
                "sample_dt_s": plan.stripes.sample_dt_s,
                "tail_s": plan.stripes.tail_s,
                "runs": len(self.runs),
                "failed_runs": self.failed,
                "fit": self.fit.to_dict(m.scale, m.unit),
                "stripes": self.stripes.to_dict(orient="records"),
                "records": self.plan.records.to_dict(orient="records"),
                "notes": list(plan.notes),
            }
        )


def run_fragility(
    plan: FragilityPlan,
    executor: Executor | None = None,
    *,
    allow_large: bool = False,
    progress: bool = True,
    on_round: Callable[[str], None] | None = None,
    folder: StudyFolder | None = None,
) -> FragilityResult:
    """Run the stripes (extending them as the plan says), fit and return the result.

    With a ``folder`` (:class:`rockyade.runner.study_folder.StudyFolder`) each run is written to
    its journal as it ends, and a run it holds from an earlier, interrupted analysis of the
    same plan is read back rather than run (:func:`rockyade.assess.stripes.run_stripes`). One
    Ctrl-C stops the analysis, between two rounds of stripes as well as within one.

    Raises
    ------
    InputError
        A run above the runner's cost limits (``allow_large`` lifts them).
    StripesInterruptedError
        Ctrl-C; its ``rows`` are the runs that finished, its ``plan`` this plan.
    """
    from rockyade.runner.stopping import StopRequest

    executor = executor or Executor("local", 2)
    try:
        with StopRequest(raise_on_second=executor.in_process) as stop:
            return _run_fragility(plan, executor, allow_large, progress, on_round, folder, stop)
    except StripesInterruptedError as exc:
        exc.plan = plan  # its rows read with the plan's measure
        raise


def _run_fragility(
    plan: FragilityPlan,
    executor: Executor,
    allow_large: bool,
    progress: bool,
    on_round: Callable[[str], None] | None,
    folder: StudyFolder | None,
    stop: StopRequest,
) -> FragilityResult:
    m = plan.measure
    levels = list(plan.levels_si)
    rows = run_stripes(
        plan.stripes, levels, executor, allow_large=allow_large, progress=progress, folder=folder, stop=stop
    )
    added: list[float] = []
    for _ in range(MAX_EXTRA_LEVELS if plan.extend else 0):
        table = stripe_table(runs_frame(rows, m), m.si_column)
        new = _next_level(table, m.si_column)
        if new is None:
            break
        try:
            for i in range(plan.stripes.motions.count):
                plan.stripes.load_factor(i, new)
        except InputError:
            break  # a record cannot be scaled that far: stop extending (the text says where the curve ends)
        if stop.requested:  # a Ctrl-C at the end of the last round: no new round starts
            raise StripesInterruptedError(rows, plan.stripes.motions.count, stop.now)
        if on_round is not None:
            on_round(f"extending the stripes: {m.name} = {m.shown(new):.4g} {m.unit}")
        added.append(new)
        rows += run_stripes(
            plan.stripes,
            [new],
            executor,
            first_index=len(rows),
            allow_large=allow_large,
            progress=progress,
            done_rows=rows,
            folder=folder,
            stop=stop,
        )
    if stop.requested:  # a Ctrl-C after the last run finished: the answer is not given as complete
        raise StripesInterruptedError(rows, 0, stop.now)
    runs = runs_frame(rows, m)
    stripes = stripe_table(runs, m.si_column)
    if m.column != m.si_column:
        stripes.insert(1, m.column, stripes[m.si_column] / m.scale)
    fit = fit_stripes(runs, m.si_column)
    return FragilityResult(plan, runs, stripes, fit, added)


def _next_level(table: pd.DataFrame, column: str) -> float | None:
    """The level to add (module docstring), or None."""
    done = table[table["n_runs"] > 0]
    if done.empty:
        return None
    top, bottom = done.iloc[-1], done.iloc[0]
    if top.fraction < 0.5:
        return float(top[column]) * EXTEND_RATIO
    if bottom.fraction > 0.5:
        return float(bottom[column]) / EXTEND_RATIO
    return None
