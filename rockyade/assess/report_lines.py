"""Fragility analyses and assessments in words, as ``rockyade fragility`` and ``rockyade assess``
print them."""

from __future__ import annotations

import math

from rockyade.assess.assessment import Assessment
from rockyade.assess.code import NOT_APPLICABLE, Q_CLAUSE, VERIFIED, Check
from rockyade.assess.directions import load_sides, toward_loaded_side
from rockyade.assess.fragility_analysis import FragilityPlan, FragilityResult
from rockyade.assess.stripes import collapse_rule
from rockyade.constants import CODE_GRAVITY as G
from rockyade.limit.crushing import STRESS_BLOCK
from rockyade.limit.report_text import code_basis_lines, hinge_words, plural, sliding_words


def _pct(x: float) -> str:
    return "-" if math.isnan(x) else f"{100 * x:.0f} %"


def plan_lines(plan: FragilityPlan) -> list[str]:
    """What a fragility analysis will run: records, load factors, levels, collapse, solver."""
    s, m = plan.stripes, plan.measure
    levels = ", ".join(f"{m.shown(v):.3g}" for v in plan.levels_si)
    lines = [
        f"records: {s.motions.describe()}; a load factor multiplies a record's accelerations as read",
        f"stripes of {m.name} ({m.unit}): {levels} ({plan.levels_source})"
        + ("; extended while the median is outside them" if plan.extend else ""),
        f"runs: {s.solver.name}, each record's duration + {s.tail_s:g} s, sampled at {s.sample_dt_s:g} s; "
        f"collapse: {collapse_rule(s.scene, s.fallen_blocks)}",
    ]
    lines.extend(f"note: {n}" for n in plan.notes)
    return lines


def fit_lines(result: FragilityResult, what: str = "") -> list[str]:
    """The stripes and the fit."""
    m, fit = result.measure, result.fit
    lines = [f"stripes ({m.name} in {m.unit}: collapses / runs, fraction, 95 % Wilson interval):"]
    for r in result.stripes.itertuples(index=False):
        level = getattr(r, m.si_column) / m.scale
        failed = f", {r.n_failed} failed" if r.n_failed else ""
        lines.append(
            f"  {level:8.4g}: {r.n_collapse:3d} / {r.n_runs:<3d} {_pct(r.fraction):>5} "
            f"[{_pct(r.fraction_lo)}, {_pct(r.fraction_hi)}]{failed}"
        )
    f = fit.fragility
    name = f"{what}{m.name}"
    if f.status == "fitted":
        lo, hi = (v / m.scale for v in fit.median_interval_si)
        b_lo, b_hi = fit.beta_interval
        band = f" (90 % bootstrap {lo:.3g}-{hi:.3g})" if not math.isnan(lo) else " (no bootstrap band)"
        beta_band = f" ({b_lo:.2g}-{b_hi:.2g})" if not math.isnan(b_lo) else ""
        lines.append(
            f"lognormal fit: median {name} = {m.shown(f.median):.4g} {m.unit}{band}, beta = {f.beta:.3g}{beta_band}"
        )
        if fit.extrapolated:
            lines.append("  note: the median is outside the tested levels: the curve is extrapolated there")
    elif f.status == "separated":
        lines.append(
            f"no slope: every collapsing run is above every other, a threshold near {name} = "
            f"{m.shown(f.median):.4g} {m.unit} (more records or closer levels give a curve)"
        )
    else:
        lines.append(f"no fit: {f.status}")
    lines += [f"  note: {note}" for note in fit.notes]
    if result.levels_added:
        added = ", ".join(f"{m.shown(v):.3g}" for v in result.levels_added)
        lines.append(f"levels added to bracket the median: {added} {m.unit}")
    if result.failed:
        reasons = result.runs.loc[result.runs.status == "failed", "failure_reason"].astype(str)
        lines.append(
            f"{result.failed} of {len(result.runs)} runs failed (left out of every count); the most frequent "
            f"reason: {reasons.value_counts().index[0]}"
        )
    return lines


def fragility_lines(result: FragilityResult, source: str) -> list[str]:
    """The text of ``rockyade fragility``."""
    return [f"fragility of {source}", *plan_lines(result.plan), *fit_lines(result)]


def _check_line(check: Check) -> str:
    unit = check.unit
    if check.status == NOT_APPLICABLE:
        return f"  {check.name}: {check.inequality}: not applicable ({check.reason})\n    clause: {check.source}"
    t = check.terms
    q_words = f" (q = {t['q']:g}, {Q_CLAUSE})" if "q" in t else ""
    demand = check.demand_text + (q_words if check.quantity == "a0*" else "")
    word = "verified" if check.status == VERIFIED else "NOT VERIFIED"
    return (
        f"  {check.name}: {check.quantity} = {check.capacity:.4g} {unit} against {demand}: {word} "
        f"(capacity / demand {check.ratio:.3g}; met up to ag = {check.ag_capacity_m_s2 / G:.4g} g)"
        f"\n    clause: {check.source}"
    )


def _examined(a: Assessment) -> str:
    """Which directions were examined, for the verdict line."""
    if a.direction_asked:
        return f" (the only one examined: --direction {a.direction_asked})"
    return " (the lower a0* of +x and -x)"


def _load_side_words(a: Assessment) -> str:
    """The side each load bears on, in words (:func:`rockyade.assess.assessment.load_sides`)."""
    sides = load_sides(a.limit)
    if not sides:
        return "no load on the moving blocks"
    words = []
    for q in sides[:3]:
        where = "on its axis" if q["side"] == "axis" else f"{abs(q['offset_m']):.4g} m towards {q['side']} of its axis"
        words.append(f"load {q['load']} bears on {q['block']} {where}")
    return ", ".join(words) + (" ..." if len(sides) > 3 else "")


def loaded_side_line(a: Assessment) -> str:
    """One line when the governing mechanism turns towards the side a load bears on (a floor's or a
    roof's, whose bearing may hold the wall that way), naming the options that model it; else ""."""
    loads = toward_loaded_side(a.limit)
    model = a.limit.model
    restrained = any(model.fixed[i] for itf in model.interfaces for i in (itf.a, itf.b) if i >= 0)
    if not loads or restrained:  # a scene with restraints models what holds the wall already
        return ""
    names = ", ".join(f"load {k}" for k in loads[:3])
    other = "-x" if a.limit.direction == "+x" else "+x"
    near_far = "restrained-far" if a.limit.direction == "+x" else "restrained-near"
    return (
        f"note: the governing mechanism turns towards {a.limit.direction}, the side {names} bears on: if that is a "
        f"floor or a roof that holds the wall's top, model it (rockyade build wall-section --top floor, or --top "
        f"{near_far}: a restraint on that face) or check the other direction alone (--direction {other})"
    )


def assessment_lines(a: Assessment, source: str) -> list[str]:
    """The text of ``rockyade assess``: the mechanism, its quantities and the code's checks
    (:func:`dynamic_lines` gives the dynamic part)."""
    lim, kin = a.limit, a.limit.kinematic
    fc_from = f" ({a.fc_source})" if a.fc_source else ""
    lines = [
        f"assessment of {source}: NTC 2018 kinematic method (NTC 2018 8.7.1, Circolare 2019 C8.7.1), FC = {a.fc:g}"
        + fc_from,
        f"site: {a.site.describe()}; mechanism {a.position.describe()}",
        f"g = {G:g} m/s^2 (standard gravity) throughout the check (ag in g and a0* = alpha0 g / (e* FC): the verdict "
        "does not depend on it), as for records given in g; the blocks' weights use the mechanics' 9.81 m/s^2",
    ]
    if lim.status == "no_mechanism":
        lines.append("limit analysis: no horizontal acceleration makes it collapse (no mechanism): no code check")
        return lines
    assert kin is not None and lim.mechanism is not None and lim.load_multiplier is not None
    mech, model = lim.mechanism, lim.model
    other = ""
    if a.other_direction is not None and a.other_direction.load_multiplier is not None:
        o = a.other_direction
        o_a0 = o.kinematic.a0_star_m_s2 if o.kinematic is not None else math.nan
        check = a.other_analysis.friction_check if a.other_analysis is not None else None
        rule = ""
        if check is not None and check.coulomb_multiplier is not None:
            rule = (
                f" (it slides with friction: {check.taken}; associated {check.associated:.4f}, "
                f"coulomb {check.coulomb_multiplier:.4f})"
            )
        other = f"; towards {o.direction}: alpha0 = {o.load_multiplier:.4f}{rule}, a0* = {o_a0:.4g} m/s^2"
    n = int(mech.moving.sum())
    joints = f"{plural(len(mech.hinges), 'hinge')}, {plural(len(mech.sliding), 'sliding joint')}"
    lines.append(
        f"mechanism (limit analysis, load towards {lim.direction}{other}): {plural(n, 'block')} "
        f"move{'s' if n == 1 else ''}, {joints}"
    )
    lines += model.load_lines()
    lines += ["  " + hinge_words(model, h) for h in mech.hinges[:5]]
    lines += ["  " + sliding_words(model, s, mech.velocities) for s in mech.sliding[:5]]
    if a.analysis is not None:
        lines += code_basis_lines(a.analysis)
    side = loaded_side_line(a)
    if side:
        lines.append(side)
    lines.append(
        f"kinematic quantities: alpha0 = {kin.alpha0:.4f}; M* = {kin.M_star_kg:.4g} kg, e* = {kin.e_star:.4f}; "
        f"a0* = alpha0 g / (e* FC) = {kin.a0_star_m_s2:.4g} m/s^2"
    )
    if kin.d0_star_m is not None:
        lines.append(
            f"  nonlinear: d0* = {kin.d0_star_m:.4g} m, du* = 0.4 d0* = {kin.du_star_m:.4g} m, ds* = "
            f"{kin.ds_star_m:.4g} m, as* = {kin.as_star_m_s2:.4g} m/s^2, Ts = 2 pi sqrt(ds*/as*) = {kin.Ts_s:.4g} s"
            + ("" if a.position.method == "circolare2009" else " (the 2009 form's period; the 2019 checks take T_SLV)")
        )
    else:
        lines.append(f"  nonlinear: none ({kin.nonlinear_note})")
    lines.append("checks made:")
    lines += [_check_line(c) for c in a.checks]
    crushing = a.analysis.crushing if a.analysis is not None else None
    if crushing is not None:
        rigid = crushing.history[0] if crushing.history else math.nan
        taken = (
            "the rigid model's multiplier is taken: with the hinges moved the coulomb iteration settled higher"
            if a.analysis is not None and a.analysis.rigid is not None and lim is a.analysis.rigid.for_code
            else f"alpha0 = {kin.alpha0:.4f} with the hinges moved against {rigid:.4f} with rigid ones"
        )
        lines.append(
            f"  masonry crushing at the hinges, fm = {crushing.fm_MPa:g} MPa: {taken}\n    clause: {STRESS_BLOCK}"
        )
    cap = a.code_capacity_ag_m_s2
    site_ag = a.site.ag_m_s2 / G
    lines.append(
        f"code verdict: {a.verdict.upper() if a.verdict != VERIFIED else 'verified'}"
        + (f" (the code's capacity is ag = {cap / G:.4g} g; the site's ag is {site_ag:.4g} g)" if cap == cap else "")
        + f", governed by the mechanism towards {lim.direction}{_examined(a)}; {_load_side_words(a)}"
    )
    # the friction caveat holds for any finite friction (a rocking mechanism can be too high as well)
    lines += [f"note: {note}" for note in lim.notes]
    lines += [f"note: {note}" for note in a.notes if not note.startswith("not made: ")]
    not_made = [note.removeprefix("not made: ") for note in a.notes if note.startswith("not made: ")]
    if not_made:
        lines.append("checks not made:")
        lines += [f"  {note}" for note in not_made]
    return lines


def dynamic_lines(a: Assessment) -> list[str]:
    """The dynamic part of ``rockyade assess``'s text (after its plan)."""
    if a.dynamic is None:
        return ["dynamics: not run (--static-only)"]
    site_ag = a.site.ag_m_s2 / G
    cap = a.code_capacity_ag_m_s2
    lines: list[str] = []
    d = a.dynamic
    lines.append(f"  {len(d.runs)} runs of {d.plan.stripes.solver.name} done")
    at = a.demand_fraction()
    assert at is not None
    lines.append(
        f"  at the code's demand (lambda = 1, ag = {site_ag:.4g} g): {at['n_collapse']} of {at['n_runs']} records "
        f"collapse the wall ({_pct(at['fraction'])}, 95 % Wilson {_pct(at['fraction_lo'])}-{_pct(at['fraction_hi'])})"
    )
    lines += ["  " + line for line in fit_lines(d, what="")]
    ratio = a.median_over_code
    if not math.isnan(ratio):
        sense = (
            f"the code is conservative for this wall (its capacity is {1 / ratio:.2f} of the dynamic median)"
            if ratio >= 1
            else f"the code is NOT conservative for this wall (its capacity is {1 / ratio:.2f} x the dynamic median)"
        )
        lines.append(
            f"  dynamic median / code capacity = {d.fit.fragility.median / G:.4g} g / {cap / G:.4g} g = {ratio:.3g}: "
            + sense
        )
    return lines


def pushover_lines(a: Assessment) -> list[str]:
    """The reference DEM's pushover (``--pushover``) against the limit analysis, in words."""
    p = a.pushover
    if p is None:
        return ["pushover: not run (no mechanism)"]
    levels = p.motion.levels()
    kin = a.limit.kinematic
    assert kin is not None
    head = (
        f"pushover (reference DEM, towards {p.direction}, levels {levels[0]:.4g} to {levels[-1]:.4g} every "
        f"{levels[1] - levels[0]:.3g}, held {p.motion.hold_s:g} s; control point: {p.control_block}'s centroid):"
    )
    line = f"  {p.onset_words()}"
    if p.bound == "measured":
        onset_star = p.onset.multiplier * kin.g / (kin.e_star * kin.FC)
        line += f"; a* = {onset_star:.4g} m/s² against a0* = {kin.a0_star_m_s2:.4g} m/s²"
    return [head, line]
