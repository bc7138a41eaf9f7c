"""A verdict on a wall: the code's kinematic checks, and the rocking dynamics beside them.

1. The mechanism and its quantities by limit analysis (:func:`rockyade.limit.limit_analysis`:
   alpha0, M*, e*, a0*, the capacity curve, d0*, du*, Ts), in the direction given or, by
   default, in both, keeping the one with the smaller a0* (the earthquake shakes both ways).
2. The code's checks against the site (:mod:`rockyade.assess.code`).
3. Unless asked not to, the dynamic answer: the same scene under a spectrum-compatible
   suite scaled to the site (:func:`rockyade.assess.motions.ec8_suite`, the site's EC8
   spectrum) or under the user's records, each scaled to the site's PGA ag S (EN 1998-1
   3.2.1: ag S is the expected peak ground acceleration on the site's ground), at load
   factors lambda on that scaling (stripes; lambda = 1 is the code's demand). The intensity
   of a run is lambda ag (:mod:`rockyade.assess.measures`, ``ag``). Reported: the fraction
   of the records that collapse the wall at the code's demand (lambda = 1), the fragility
   median and beta in ag, and the ratio of that median to the code's capacity expressed in
   the same ag (the largest ag at which one of its checks is met): above 1 the code is
   conservative for this wall, below 1 it is not.

A mechanism at a height of a building is shaken by its floor, not by the ground: the
dynamic part runs ground motions at the scene's base, so it is refused there (the code's
check at height stands alone).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from rockyade.assess.code import (
    NOT_APPLICABLE,
    Check,
    check_code,
    checks_not_made,
    code_capacity_ag,
    code_checks,
    verdict,
)
from rockyade.assess.directions import load_sides, toward_loaded_side
from rockyade.assess.fragility_analysis import (
    FragilityPlan,
    FragilityResult,
    SceneCannotStandError,
    default_solver,
    run_fragility,
)
from rockyade.assess.measures import Measure
from rockyade.assess.motions import MotionSet, RecordFiles, ec8_suite
from rockyade.assess.pushover import PushoverCheck, run_pushover
from rockyade.assess.site import AnySite, Position, Site
from rockyade.assess.stripes import (
    DEFAULT_SAMPLE_DT_S,
    DEFAULT_TAIL_S,
    StripePlan,
    check_fallen_blocks,
    record_measures,
)
from rockyade.constants import CODE_GRAVITY as G
from rockyade.errors import InputError, SolverFailedError
from rockyade.io.strict_json import finite_or_null
from rockyade.limit import LimitResult, limit_analysis
from rockyade.limit.kinematic import check_fc
from rockyade.runner import Executor
from rockyade.runner.study_folder import StudyFolder
from rockyade.scene import Scene
from rockyade.solvers import as_solver
from rockyade.solvers.base import Solver

#: Default load factors on the site's scaling (1: the code's demand), ratio sqrt 2.
DEFAULT_LOAD_FACTORS = (0.35, 0.5, 0.71, 1.0, 1.41, 2.0, 2.83)
#: Records of the default suite, and its seed.
DEFAULT_COUNT = 20
DEFAULT_SEED = 1
#: The keys of the code's quantities at the top of the JSON.
QUANTITY_KEYS = ("alpha0", "e_star", "M_star_kg", "a0_star_m_s2", "d0_star_m", "du_star_m", "Ts_s")


@dataclass(frozen=True)
class DynamicSettings:
    """The dynamic part of an assessment.

    Attributes
    ----------
    records
        The user's records (each scaled to the site's ag S at lambda = 1), or None for a
        synthetic suite compatible with the site's spectrum.
    count, seed
        The suite's records and seed.
    solver
        A Solver or a name (default: Housner for a single block, the reference DEM otherwise).
    load_factors
        lambda on the site's scaling; 1 is always added.
    extend
        Extend the stripes while the median is outside them (:mod:`rockyade.assess.fragility_analysis`).
    fallen_blocks, sample_dt_s, tail_s
        As :func:`rockyade.assess.fragility_analysis.fragility_plan` takes them.
    """

    records: RecordFiles | None = None
    count: int = DEFAULT_COUNT
    seed: int = DEFAULT_SEED
    solver: Solver | str | None = None
    load_factors: tuple[float, ...] = DEFAULT_LOAD_FACTORS
    extend: bool = True
    fallen_blocks: int = 1
    sample_dt_s: float = DEFAULT_SAMPLE_DT_S
    tail_s: float = DEFAULT_TAIL_S


def check_load_factors(values: tuple[float, ...]) -> tuple[float, ...]:
    """Load factors in (0, 100], 2 to 50 of them, sorted with 1 among them."""
    if not 1 <= len(values) <= 50:
        raise InputError("--load-factors", f"needs 1 to 50 values, got {len(values)}")
    bad = [v for v in values if not (math.isfinite(v) and 0.0 < v <= 100.0)]
    if bad:
        raise InputError("--load-factors", f"must be in (0, 100], got {bad[0]:g}")
    return tuple(sorted({float(v) for v in values} | {1.0}))


@dataclass
class Assessment:
    """The answer of :func:`assess` (module docstring).

    Attributes
    ----------
    code
        ``ntc2018``.
    fc
        The confidence factor FC.
    site, position
        The demand's inputs.
    limit
        The governing limit analysis (its mechanism and the code's quantities).
    other_direction
        The other direction's limit analysis (when both were solved), for the record (the answer its
        code's quantities take, as ``limit``).
    checks
        The code's checks.
    dynamic
        The fragility in ag (None with ``static_only``).
    pushover
        The reference DEM's pushover at the mechanism's control point (None unless asked:
        :func:`add_pushover`).
    fc_source
        Where FC comes from (the knowledge level and its clause, or ``--fc``).
    analysis
        The governing direction's limit analysis as solved (``limit`` is its ``for_code``: the coulomb
        pass's where the mechanism slides with friction and it is lower; ``friction_check`` and
        ``crushing`` say how it was chosen).
    direction_asked
        ``+x`` or ``-x`` when one direction was asked for, None for both.
    other_analysis
        The other direction's limit analysis as solved (``other_direction`` is its ``for_code``).
    """

    code: str
    fc: float
    site: AnySite
    position: Position
    limit: LimitResult
    other_direction: LimitResult | None
    checks: list[Check]
    dynamic: FragilityResult | None = None
    notes: list[str] = field(default_factory=list)
    pushover: PushoverCheck | None = None
    fc_source: str = ""
    analysis: LimitResult | None = None
    direction_asked: str | None = None
    other_analysis: LimitResult | None = None

    @property
    def verdict(self) -> str:
        """``verified``, ``not verified``, ``not applicable`` or ``no mechanism``."""
        if self.limit.status == "no_mechanism":
            return "no mechanism"
        return verdict(self.checks)

    @property
    def code_capacity_ag_m_s2(self) -> float:
        """The largest ag at which a check is met, m/s^2 (:func:`rockyade.assess.code.code_capacity_ag`)."""
        return code_capacity_ag(self.checks)

    def demand_fraction(self) -> dict[str, float] | None:
        """Collapses at the code's demand (lambda = 1): count, runs, fraction, Wilson 95 %."""
        if self.dynamic is None:
            return None
        return self.dynamic.fraction_at(self.site.ag_m_s2)

    @property
    def median_over_code(self) -> float:
        """The dynamic median ag over the code's capacity ag (NaN where either is missing)."""
        if self.dynamic is None or not self.dynamic.fit.fitted:
            return math.nan
        return self.dynamic.fit.fragility.median / self.code_capacity_ag_m_s2

    def to_dict(self) -> dict[str, object]:
        """JSON-ready (the code's quantities at the top; each check with its demand, capacity,
        verdict and source; strict: a number that does not exist is null)."""
        lim = self.limit.to_dict()
        out: dict[str, object] = {
            "code": self.code,
            "FC": self.fc,
            "FC_source": self.fc_source,
            "status": self.limit.status,
            "verdict": self.verdict,
            "verdict_rule": "verified when one of the checks that apply is met (the linear check with q and the "
            "nonlinear check are two ways of checking the mechanism)",
            "site": self.site.to_dict(),
            "g_m_s2": G,
            "g_meaning": "the one g of the check: ag in g and a0* = alpha0 g / (e* FC) (the verdict does not depend "
            "on it); records in g are read with standard gravity 9.80665 m/s^2",
            "position": self.position.to_dict(),
            "direction": self.limit.direction,
            "load_multiplier": self.limit.load_multiplier,
        }
        out.update({k: lim.get(k) for k in QUANTITY_KEYS})
        out["kinematic"] = lim.get("kinematic")
        keys = ("mechanism", "hinges", "sliding", "friction_angle_deg", "friction_rule", "iterations")
        out["mechanism"] = {k: lim[k] for k in keys}
        out["limit_notes"] = lim["notes"]
        out["loads"] = lim["loads"]
        full = self.analysis.to_dict() if self.analysis is not None else lim
        out["code_friction"] = full.get("code_friction")
        out["fm_MPa"] = full.get("fm_MPa")
        out["crushing"] = full.get("crushing")
        out["load_sides"] = load_sides(self.limit)
        out["governing"] = {
            "direction": self.limit.direction,
            "directions_examined": [self.direction_asked] if self.direction_asked else ["+x", "-x"],
            "towards_a_loaded_side": toward_loaded_side(self.limit),
        }
        out["rigid_body_mechanism"] = rigid_body_mechanism(self.limit)
        if self.other_direction is not None:
            o = self.other_direction
            check = self.other_analysis.friction_check if self.other_analysis is not None else None
            out["other_direction"] = {
                "direction": o.direction,
                "status": o.status,
                "alpha0": o.load_multiplier,
                "a0_star_m_s2": o.kinematic.a0_star_m_s2 if o.kinematic is not None else None,
                "friction_rule": o.friction_rule,
                "code_friction": check.to_dict() if check is not None else None,
            }
        out["checks"] = [c.to_dict() for c in self.checks]
        cap = self.code_capacity_ag_m_s2
        out["code_capacity_ag_m_s2"] = cap
        out["code_capacity_ag_g"] = cap / G
        out["dynamic"] = None
        if self.dynamic is not None:
            fit = self.dynamic.fit
            out["dynamic"] = {
                **self.dynamic.to_dict(),
                "at_code_demand": self.demand_fraction(),
                "median_ag_g": fit.fragility.median / G,
                "beta": fit.fragility.beta,
                "median_over_code_capacity": self.median_over_code,
                "median_over_code_capacity_meaning": "the dynamic median ag over the largest ag at which a code "
                "check is met: above 1 the code is conservative for this wall, below 1 it is not",
            }
        out["pushover"] = None
        if self.pushover is not None:
            p = self.pushover.to_dict()
            out["pushover_onset_lambda"] = p["pushover_onset_lambda"]
            out["pushover_onset_minus_alpha0_pct"] = p["pushover_onset_minus_alpha0_pct"]
            out["pushover"] = p
        out["notes"] = list(self.notes)
        return finite_or_null(out)


#: Why an NTC 2018 site's dynamics need the user's records.
NTC_SUITE_MESSAGE = (
    "the synthetic suite is generated to match an EC8 spectrum (type and ground); for an NTC 2018 site give "
    "--records (a folder of the site's records, e.g. spectrum-compatible ones), or --static-only, or the EC8 "
    "spectrum (--spectrum ec8 --spectrum-type --ground)"
)


def rigid_body_mechanism(limit: LimitResult) -> dict[str, Any] | None:
    """When the mechanism turns several blocks as one rigid body (a wall's courses rotating
    together), the code's e* of the blocks as separate P_i beside that of the same body as one
    block, and what it means (a note); None otherwise.

    The kinematic method counts each block as a P_i at its centroid, so n courses that turn as
    one give e* = (1/4) / (1/3 - 1/(12 n^2)) -> 0.75, while the same wall as one block has
    e* = 1; a0* = alpha0 g / (e* FC) is then 1 / e* times the monolith's for the same motion. Such
    courses are not expected to act as separate blocks dynamically: the DEMs find a wall in
    courses rocking as its monolith when its mechanism turns all courses as one
    (docs/howto/is-this-wall-safe.md).
    """
    kin, mech = limit.kinematic, limit.mechanism
    if kin is None or mech is None:
        return None
    model = limit.model
    moving = np.flatnonzero(mech.moving)
    if moving.size < 2:
        return None
    v = mech.velocities
    omega = v[moving, 2]
    scale = max(float(np.max(np.abs(v[moving, :2]))), 1e-300)
    if np.ptp(omega) > 1e-9 * max(float(np.max(np.abs(omega))), 1e-300):
        return None
    ref = int(moving[0])
    c = model.centroids_m
    for i in moving[1:]:  # v_i = v_ref + omega x (c_i - c_ref): one rigid-body motion
        r = c[i] - c[ref]
        expected = v[ref, :2] + omega[0] * np.array([-r[1], r[0]])
        if np.max(np.abs(v[i, :2] - expected)) > 1e-7 * scale:
            return None
    d = 1.0 if limit.direction == "+x" else -1.0
    own_m = model.masses_kg if model.block_masses_kg is None else model.block_masses_kg
    own_c = model.centroids_m if model.block_centroids_m is None else model.block_centroids_m
    mass = float(own_m[moving].sum())
    centre = np.average(own_c[moving], axis=0, weights=own_m[moving])
    points = [(mass, centre)] + [
        (float(q.mass_kg), np.asarray(q.point_m, dtype=float))
        for q in model.given_loads
        if q.mass_kg and int(q.block) in set(moving.tolist())
    ]

    def dx(p: np.ndarray) -> float:
        r = p - c[ref]
        return d * float(v[ref, 0] - omega[0] * r[1])

    s1 = sum(m * dx(p) for m, p in points)
    s2 = sum(m * dx(p) ** 2 for m, p in points)
    total = sum(m for m, _ in points)
    e_one = s1 * s1 / s2 / total
    a0_one = kin.alpha0 * kin.g / (e_one * kin.FC)
    names = [model.names[i] for i in moving]
    note = (
        f"the mechanism turns {len(names)} blocks ({names[0]} ... {names[-1]}) as one rigid body: they are not "
        "expected to act as separate blocks dynamically (the DEMs find a wall in courses rocking as its monolith "
        f"when its mechanism turns all courses as one). The code's e* = {kin.e_star:.4g} counts each block as a P_i; "
        f"the same body as one block has e* = {e_one:.4g}, so a0* = {kin.a0_star_m_s2:.4g} m/s^2 is "
        f"{e_one / kin.e_star:.3g} times the monolith's {a0_one:.4g} m/s^2 for the same motion: the capacity the "
        "courses add is the code's lumping, not the dynamics'"
    )
    return {
        "blocks": names,
        "e_star_blocks": kin.e_star,
        "e_star_one_body": e_one,
        "a0_star_one_body_m_s2": a0_one,
        "note": note,
    }


def _limit(
    scene: Scene,
    direction: str | None,
    friction_angle_deg: float | None,
    sliding: bool,
    fc: float,
    rule: str | None = None,
    fm_MPa: float | None = None,
) -> tuple[LimitResult, LimitResult | None]:
    """(governing, other) as solved: the direction given, or both, keeping the smaller a0* of the answer
    the code takes (:attr:`rockyade.limit.LimitResult.for_code`). ``rule`` None: associated with a
    coulomb pass where the mechanism slides with friction (the lower multiplier taken)."""
    directions = [direction] if direction else ["+x", "-x"]
    results = [
        limit_analysis(
            scene,
            d,
            friction_angle_deg=friction_angle_deg,
            sliding=sliding,
            fc=fc,
            friction_rule=rule or "associated",
            coulomb_check=rule is None,
            fm_MPa=fm_MPa,
        )
        for d in directions
    ]
    if any(r.status == "unstable" for r in results):
        raise SceneCannotStandError(scene.source)
    for r in results:
        if r.status == "not_converged":
            raise SolverFailedError(
                f"the limit analysis with the coulomb friction rule did not converge towards {r.direction} "
                f"({r.reason}): no code check; the associated rule (the default) bounds it from above"
            )
    collapsing = [r for r in results if r.status == "collapse"]
    if not collapsing:
        return results[0], (results[1] if len(results) > 1 else None)

    def a0(r: LimitResult) -> float:
        kin = r.for_code.kinematic
        return kin.a0_star_m_s2 if kin is not None else math.inf

    best = min(collapsing, key=a0)
    other = next((r for r in results if r is not best), None)
    return best, other


def dynamic_plan(
    scene: Scene, site: AnySite, settings: DynamicSettings, executor: Executor, progress: bool = True
) -> FragilityPlan:
    """The stripes in ag (module docstring); records generated or read now, nothing run."""
    solver = as_solver(settings.solver or default_solver(scene))
    fallen = check_fallen_blocks(scene, settings.fallen_blocks)
    motions: MotionSet
    if settings.records is None:
        if not isinstance(site, Site):
            raise InputError("--records", NTC_SUITE_MESSAGE)
        motions = ec8_suite(site.spectrum_type, site.ground, site.ag_m_s2, settings.count, settings.seed)
    else:
        motions = settings.records
        motions.check_site(site.to_dict())  # a selection scales its records to one site's spectrum
    table = record_measures(motions, None, executor, progress)
    table.insert(0, "record", [motions.label(i) for i in range(motions.count)])
    if settings.records is None:
        im = np.full(motions.count, site.ag_m_s2)  # the suite's own ag
        how = f"the suite's target ag = {site.ag_m_s2 / G:.4g} g for every record"
    elif settings.records.scale_factors is not None:
        im = np.full(motions.count, site.ag_m_s2)  # the selection's factors scale each record to the site
        how = "each record scaled by its selection's factor to the site's spectrum (rockyade motion select)"
    else:
        im = table["pga_m_s2"].to_numpy() / site.S  # scaled so that PGA = ag S at lambda = 1
        how = f"each record's PGA / S (S = {site.S:g}): lambda = 1 scales its PGA to ag S"
    table["im_si"] = im
    measure = Measure("ag")
    stripes = StripePlan(
        scene,
        motions,
        measure,
        tuple(float(v) for v in im),
        tuple(float(v) for v in table["duration_s"]),
        solver,
        fallen,
        settings.sample_dt_s,
        settings.tail_s,
    )
    factors = check_load_factors(settings.load_factors)
    levels = tuple(f * site.ag_m_s2 for f in factors)
    for level in levels:
        for i in range(motions.count):
            stripes.load_factor(i, level)
    source = f"load factors {', '.join(f'{f:g}' for f in factors)} on the site's scaling ({how})"
    return FragilityPlan(stripes, table, levels, source, settings.extend)


def _raised_hinge_note(result: LimitResult, position: Position) -> str:
    """At height, a note where the mechanism turns about hinges above the scene's base: the code's Z is
    the height of the lines about which the mechanism's blocks turn on the rest of the structure
    (Circolare 2019 C8.7.1.2.1.5), which ``--z`` is taken to be as given; empty otherwise."""
    mech = result.mechanism
    if not position.at_height or mech is None:
        return ""
    moving = {name for name, m in zip(result.model.names, mech.moving, strict=True) if m}
    heights = sorted({round(h.point_m[1], 6) for h in mech.hinges if (h.a in moving) != (h.b in moving)})
    if not heights or heights[0] <= 1e-6:  # a hinge on the base: Z is the scene's base
        return ""
    where = ", ".join(f"{y:g}" for y in heights)
    z = position.z_m or 0.0
    return (
        f"the mechanism turns on the rest of the structure about hinges at y = {where} m of the scene, above its "
        f"base: the code's Z (Circolare 2019 C8.7.1.2.1.5) is the height of those lines above the foundation; "
        f"--z {z:g} was taken as given: if it is the height of the scene's base, give --z {z + heights[0]:g} (or "
        "the height of the lines' barycentre) instead"
    )


def assess(
    scene: Scene,
    site: AnySite,
    *,
    fc: float,
    fc_source: str = "",
    code: str = "ntc2018",
    position: Position | None = None,
    direction: str | None = None,
    friction_angle_deg: float | None = None,
    sliding: bool = True,
    friction_rule: str | None = None,
    fm_MPa: float | None = None,
    dynamic: DynamicSettings | None = None,
    executor: Executor | None = None,
    allow_large: bool = False,
    progress: bool = True,
    on_plan: Callable[[FragilityPlan], None] | None = None,
) -> Assessment:
    """The code's verdict on a scene's mechanism and the dynamics beside it (module docstring).

    Parameters
    ----------
    scene
        The wall (any scene).
    site
        The site's spectrum.
    fc
        The confidence factor FC, the engineer's choice (no default): from the knowledge level,
        :func:`rockyade.assess.code.confidence_factor` (LC1 1.35, LC2 1.20, LC3 1.00).
    fc_source
        Where it comes from, for the output.
    code
        ``ntc2018``.
    position
        At ground level (default) or at a height of a building.
    direction
        ``+x``, ``-x``, or None for both (the smaller a0* governs).
    friction_angle_deg, sliding, friction_rule
        The joints of the limit analysis (:func:`rockyade.limit.limit_analysis`); ``friction_rule``
        None: associated, with a coulomb pass where its mechanism slides with friction, the code taking
        the lower multiplier; a coulomb rule that does not converge raises SolverFailedError.
    fm_MPa
        The masonry's compressive strength at the hinges, MPa (None: rigid blocks;
        :mod:`rockyade.limit.crushing`).
    dynamic
        The dynamic part's settings; None: the code's checks only.
    executor
        Where the runs go (default: 2 local processes).
    allow_large
        Run above the runner's cost limits.
    on_plan
        Called with the dynamic plan before anything runs (to print its cost).

    Raises
    ------
    SceneCannotStandError
        The scene cannot stand under gravity.
    InputError
        Bad input; the dynamic part for a mechanism at height.
    """
    check_code(code)
    position = position or Position()
    if dynamic is not None and position.at_height:
        raise InputError(
            "--static-only",
            "the dynamic part shakes the scene's base with ground motions; a mechanism at height is shaken by its "
            "floor (not modelled): pass --static-only for the code's check at height",
        )
    fc = check_fc(fc)
    solved, other = _limit(scene, direction, friction_angle_deg, sliding, fc, friction_rule, fm_MPa)
    best = solved.for_code
    checks = code_checks(best.kinematic, site, position) if best.kinematic is not None else []
    other_code = other.for_code if other is not None else None
    out = Assessment(code, fc, site, position, best, other_code, checks, fc_source=fc_source, analysis=solved)
    out.direction_asked, out.other_analysis = direction, other
    if best.status == "no_mechanism":
        out.notes.append("no horizontal acceleration makes the scene collapse statically: no code check")
    if any(c.status == NOT_APPLICABLE for c in checks):
        out.notes.extend(f"{c.name}: not applicable ({c.reason})" for c in checks if c.status == NOT_APPLICABLE)
    rigid = rigid_body_mechanism(best)
    if rigid is not None:
        out.notes.append(rigid["note"])
    raised = _raised_hinge_note(best, position)
    if raised:
        out.notes.append(raised)
    out.notes.extend(checks_not_made(best.kinematic, position, direction, fm_MPa is not None))
    if dynamic is not None:
        add_dynamics(out, scene, dynamic, executor, allow_large=allow_large, progress=progress, on_plan=on_plan)
    return out


def add_dynamics(
    assessment: Assessment,
    scene: Scene,
    settings: DynamicSettings,
    executor: Executor | None = None,
    *,
    allow_large: bool = False,
    progress: bool = True,
    on_plan: Callable[[FragilityPlan], None] | None = None,
    folder: StudyFolder | None = None,
) -> Assessment:
    """Run the dynamic part of an assessment (module docstring) and attach it; the same
    assessment back. ``folder``: the study folder in whose journal each run is written as it
    ends, and read back on a resume (:func:`rockyade.assess.fragility_analysis.run_fragility`).

    Raises
    ------
    InputError
        A mechanism at height; a run above the runner's cost limits (``allow_large``).
    """
    if assessment.position.at_height:
        raise InputError(
            "--static-only",
            "the dynamic part shakes the scene's base with ground motions; a mechanism at height is shaken by its "
            "floor (not modelled): pass --static-only for the code's check at height",
        )
    executor = executor or Executor("local", 2)
    plan = dynamic_plan(scene, assessment.site, settings, executor, progress)
    if on_plan is not None:
        on_plan(plan)
    assessment.dynamic = run_fragility(plan, executor, allow_large=allow_large, progress=progress, folder=folder)
    return assessment


def add_pushover(assessment: Assessment, scene: Scene) -> Assessment:
    """Run the reference DEM's pushover of the governing mechanism (:mod:`rockyade.assess.pushover`)
    and attach it; the same assessment back (unchanged without a mechanism, with a note)."""
    kin = assessment.limit.kinematic
    if assessment.limit.status != "collapse" or kin is None:
        assessment.notes.append("pushover: no mechanism to push (not run)")
        return assessment
    assessment.pushover = run_pushover(scene, kin, assessment.limit.direction)
    return assessment
