"""The summary of a cross-check (:mod:`rockyade.studies.crosscheck`): collapse intensities,
paired ratios with their bootstrap intervals, the convergence in the time step, the verdict
agreement and the fragility per solver, from the runs' outcomes
(:mod:`rockyade.analysis.crosscheck_statistics`); ``index.md`` in words and numbers; the set's files.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from rockyade.analysis.crosscheck_statistics import (
    BRACKETED,
    MIN_RECORDS,
    CollapseSearch,
    MedianInterval,
    PairVerdict,
    collapse_summary,
    median_interval,
    pair_verdict,
    paired_ratios,
    ratio_decimals,
    too_few_note,
    verdict_agreement,
    without_interval,
)
from rockyade.assess.stripes import collapse_rule
from rockyade.io.atomic import atomic_open, write_json, write_text
from rockyade.runner.rows import Cells
from rockyade.studies.crosscheck.plan import CrosscheckPlan, Outcomes

#: The status of a search a partial summary finds unfinished: its bracket so far is not an answer,
#: and it is left out of the ratios.
UNFINISHED = "unfinished (the study was stopped)"


def unfinished(plan: CrosscheckPlan, outcomes: Outcomes, key: tuple[str, float, int]) -> bool:
    """Whether the search ``key`` has runs still to make (as
    :meth:`rockyade.studies.crosscheck.search.Study.pending` chooses them: a level that failed
    ends it)."""
    verdicts = outcomes.verdicts.get(key, {})
    return any(level not in verdicts for level in plan.next_levels(key[2], verdicts))


@dataclass(frozen=True)
class Summary:
    """The numbers of a cross-check (complete or partial)."""

    collapse: pd.DataFrame
    pairs: pd.DataFrame
    runs: pd.DataFrame
    fragility: list[dict[str, object]]
    verdicts: list[str]
    partial: bool


def summarise(plan: CrosscheckPlan, outcomes: Outcomes, partial: bool) -> Summary:
    """Collapse intensities, paired ratios, convergence, verdict agreement and fragility from
    the outcomes (module docstring of :mod:`rockyade.analysis.crosscheck_statistics`)."""
    m = plan.measure
    sp = plan.stripes.stripes
    scan = list(plan.scan_si)
    rows = []
    searches: dict[tuple[str, float, int], CollapseSearch] = {}
    for key in plan.searches():
        solver, f, i = key
        found = collapse_summary(outcomes.verdicts.get(key, {}), scan)
        if partial and unfinished(plan, outcomes, key):  # a bracket so far is not the search's answer
            found = replace(found, collapse_intensity=math.nan, status=UNFINISHED)
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
            pair_rows.append(
                _pair_row("dt", solver, solver, f, plan.dt_factors[0], without_interval(ratio), same, n, "", "")
            )
    failures = failed_runs(runs)
    verdicts = []
    for f in plan.dt_factors:
        for ia, a in enumerate(plan.solvers):
            for b in plan.solvers[ia + 1 :]:
                ratio = median_interval(paired_ratios(intensities(a, f), intensities(b, f)).values())
                same, n = verdict_agreement(scan_verdicts(a, f), scan_verdicts(b, f))
                v = pair_verdict(
                    a,
                    b,
                    ratio,
                    plan.tolerance,
                    dt_change if len(plan.dt_factors) > 1 else None,
                    ratio_decimals(plan.resolution),
                )
                v = _failed_verdict(a, b, f, failures) or v
                pair_rows.append(
                    _pair_row("solvers", a, b, f, f, without_interval(ratio), same, n, v.verdict, v.sentence)
                )
                if f == finest or len(plan.dt_factors) == 1:
                    verdicts.append(f"at dt x {f:g}: {v.sentence}")
    pairs = pd.DataFrame(pair_rows, columns=list(PAIR_COLUMNS))
    fragility = _fragility(plan, runs)
    return Summary(collapse, pairs, runs, fragility, verdicts, partial)


@dataclass(frozen=True)
class Failures:
    """The runs of one solver at one time-step factor that failed (no verdict).

    Attributes
    ----------
    failed, runs
        Runs that failed, and runs made.
    reasons
        The first distinct reasons, in the order of the runs (at most three).
    """

    failed: int
    runs: int
    reasons: tuple[str, ...]

    @property
    def every(self) -> bool:
        """Every run made failed."""
        return self.runs > 0 and self.failed == self.runs


def failed_runs(runs: pd.DataFrame) -> dict[tuple[str, float], Failures]:
    """(solver, dt factor) -> its failed runs, for those with at least one."""
    out: dict[tuple[str, float], Failures] = {}
    if runs.empty:
        return out
    for (solver, f), group in runs.groupby(["solver", "dt_factor"], sort=False):
        bad = group[group["collapsed"].isna()]
        if bad.empty:
            continue
        reasons: list[str] = []
        for r in bad["failure_reason"]:
            text = str(r or "").strip() or "no reason recorded"
            if text not in reasons:
                reasons.append(text)
        out[(str(solver), float(f))] = Failures(len(bad), len(group), tuple(reasons[:3]))
    return out


def _failed_verdict(a: str, b: str, f: float, failures: Mapping[tuple[str, float], Failures]) -> PairVerdict | None:
    """The verdict of a pair one of whose solvers failed every run at ``f``: no comparison (not
    "inconclusive"), the first reason said; None otherwise."""
    for s in (a, b):
        fail = failures.get((s, float(f)))
        if fail is not None and fail.every:
            return PairVerdict(
                "failed",
                f"{a} / {b}: no comparison: {s} failed every run ({fail.failed} of {fail.runs}; first reason: "
                f"{fail.reasons[0]})",
            )
    return None


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
) -> Cells:
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


def _fragility(plan: CrosscheckPlan, runs: pd.DataFrame) -> list[dict[str, object]]:
    """Per solver and dt factor, the lognormal fragility of its runs (scan and bisection)
    with its bootstrap intervals (:func:`rockyade.assess.stripe_fit.fit_stripes`)."""
    from rockyade.assess.stripe_fit import fit_stripes

    m = plan.measure
    out: list[dict[str, object]] = []
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


def _fixed(v: float, decimals: int) -> str:
    return f"{v:.{decimals}f}" if isinstance(v, (int, float)) and math.isfinite(v) else "-"


def _interval_text(r: Any, decimals: int) -> str:
    """A pairs row's interval in words: the interval, or why there is none."""
    if math.isfinite(r.ratio_low):
        return f"95 % interval {_fixed(r.ratio_low, decimals)}-{_fixed(r.ratio_high, decimals)}, {r.records} records"
    if 0 < r.records < MIN_RECORDS:
        return too_few_note(int(r.records))
    return f"{r.records} records"


def _number(value: object) -> float:
    """A number of a fit's dictionary (NaN: none)."""
    return float(value) if isinstance(value, (int, float)) else math.nan


def _bounds(value: object) -> tuple[float, float]:
    """An interval of a fit's dictionary (NaN, NaN: none)."""
    if isinstance(value, (list, tuple)) and len(value) == 2:
        return _number(value[0]), _number(value[1])
    return math.nan, math.nan


def _fmt(v: float, digits: int = 4) -> str:
    return f"{v:.{digits}g}" if isinstance(v, (int, float)) and math.isfinite(v) else "-"


def subsets_text(plan: CrosscheckPlan) -> str:
    """The solvers run on the first records only (``records_per_solver``), in words; "" when none."""
    parts = [f"{s} on the first {len(plan.records_of(s))}" for s in plan.solvers if s in plan.records_per_solver]
    return f" ({', '.join(parts)}; a pair is over the records both ran)" if parts else ""


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
        f"{100 * plan.resolution:g} %. Records: {plan.motions.describe()}{subsets_text(plan)}. Agreement: the "
        f"median ratio of two solvers' collapse intensities, paired by record, within {100 * plan.tolerance:g} % of 1 "
        "and its bootstrap "
        f"95 % interval within {200 * plan.tolerance:g} %. Time-step factors: "
        f"{', '.join(f'{f:g}' for f in plan.dt_factors)}.",
        "",
        "## Verdicts",
        "",
    ]
    lines += [f"- {v}" for v in summary.verdicts] or ["- no pair of solvers has collapse intensities to compare"]
    failures = failed_runs(summary.runs)
    if failures:
        total = sum(x.failed for x in failures.values())
        lines += [
            "",
            "## Failed runs",
            "",
            f"{total} of {len(summary.runs)} runs failed: they have no verdict, and a search stops at its bracket "
            "so far (`runs.csv`: status and failure_reason of each).",
            "",
        ]
        for (solver, f), fail in failures.items():
            lines.append(
                f"- {solver} at dt x {f:g}: {fail.failed} of {fail.runs} runs failed"
                + (" (every run)" if fail.every else "")
                + "; first reasons: "
                + "; ".join(fail.reasons)
            )
    pairs = summary.pairs
    dt_rows = pairs[pairs["kind"] == "dt"] if not pairs.empty else pairs
    d = ratio_decimals(plan.resolution)
    if len(dt_rows):
        lines += ["", "## Convergence in the time step", ""]
        for _, r in dt_rows.iterrows():
            lines.append(
                f"- {r.solver_a}: collapse intensity at dt x {r.dt_factor_a:g} / at dt x {r.dt_factor_b:g} = "
                f"{_fixed(r.median_ratio, d)} ({_interval_text(r, d)}); "
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
        interval = (
            f"{_fixed(r.ratio_low, d)}-{_fixed(r.ratio_high, d)}"
            if math.isfinite(r.ratio_low)
            else f"none ({r.records} < {MIN_RECORDS} records)"
            if 0 < r.records < MIN_RECORDS
            else "-"
        )
        lines.append(
            f"| {r.solver_a} | {r.solver_b} | {r.dt_factor_a:g} | {r.records} | {_fixed(r.median_ratio, d)} | "
            f"{interval} | {r.same_verdict_runs}/{r.compared_runs} | {r.verdict} |"
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
        median = fr.get(key, math.nan)
        if not (isinstance(median, (int, float)) and math.isfinite(median)):
            why = str(fr.get("status") or "not fitted").replace("|", "/")
            lines.append(f"| {fr['solver']} | {fr['dt_factor']:g} | {why} | - | - | - |")
            continue
        mi = _bounds(fr.get(f"median_interval_{m.unit.replace('/', '_')}"))
        bi = _bounds(fr.get("beta_interval"))
        lines.append(
            f"| {fr['solver']} | {fr['dt_factor']:g} | {_fmt(median)} | {_fmt(mi[0])}-{_fmt(mi[1])} | "
            f"{_fmt(_number(fr.get('beta')), 3)} | {_fmt(bi[0], 3)}-{_fmt(bi[1], 3)} |"
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
    plan: CrosscheckPlan, summary: Summary, folder: Path, seconds: float, extra: Mapping[str, object]
) -> None:
    """The set's files in ``folder`` (the JSON last: it says whether the set is complete)."""
    from rockyade.io.strict_json import finite_or_null

    for name, frame in (
        ("collapse_intensities.csv", summary.collapse),
        ("pairs.csv", summary.pairs),
        ("runs.csv", summary.runs),
    ):
        with atomic_open(folder / name) as fh:
            frame.to_csv(fh, index=False, float_format="%.10g", lineterminator="\n")
    if not summary.partial:
        from rockyade.figures.paired_ratios import PairedRatios

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
