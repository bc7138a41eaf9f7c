"""Collapse fragility of the four specimens over the paper's synthetic suite.

Each specimen (experimental parameters, matched calibration) under the 30 records at load
factors 0.1-1.5 (step 0.1), 25 s (20 s of record, 5 s after): the fraction of records that
overturn it at each load factor, and a lognormal fragility curve fitted by maximum
likelihood, for the reference DEM and Housner; YADE on a documented subset (specimen 2,
records 1-10, load factors 0.4, 0.8, 1.2). Intensity: the nominal PGA of the scaled suite,
load factor x ag S (ag S = 2.8 m/s^2).

The stripes are those of ``rockyade fragility`` and ``rockyade assess``
(:class:`rockyade.assess.stripes.LoadFactorStripes`, run through :mod:`rockyade.runner` by
:func:`rockyade.assess.stripes.run_stripes`: a run collapses when the block overturns), and
the curve is the one fit of :func:`rockyade.probability.fragility_curves.fit_lognormal`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from rockyade import paper
from rockyade.assess.measures import Measure
from rockyade.assess.motions import paper_suite_set
from rockyade.assess.stripes import LoadFactorStripes, StripeTask, run_stripes
from rockyade.calibration.model_stage import calibrated_model
from rockyade.constants import ACCEL_UNIT_LABELS
from rockyade.errors import InputError
from rockyade.figures import new_figure, save_figure
from rockyade.figures.canvas import accel_scale, other_accel_axis
from rockyade.figures.fragility_panels import FragilityCurve, FragilityDisplay
from rockyade.figures.styles import SOLVER_LABELS, SOLVER_STYLES
from rockyade.motion.suite_cache import suite_record
from rockyade.motion.synthetic import paper_suite
from rockyade.probability.fragility_curves import Fragility, fit_lognormal
from rockyade.runner import Executor, run_jobs
from rockyade.scene import scene_from_dict
from rockyade.solvers import as_solver
from rockyade.studies.report import Report, fmt, run_state
from rockyade.studies.specimen_scenes import block_table, scene_dict

LOAD_FACTORS = tuple(round(0.1 * k, 1) for k in range(1, 16))
RECORDS = tuple(range(1, 31))
DURATION_S = 25.0
SAMPLE_DT_S = 0.01
YADE_SUBSET = {"specimen": "2", "records": tuple(range(1, 11)), "load_factors": (0.4, 0.8, 1.2)}


def _base(key: str) -> dict:
    motion = {"type": "synthetic", "suite": "paper", "record": 1, "load_factor": 1.0}
    return scene_dict([block_table(key)], motion, DURATION_S, SAMPLE_DT_S, "matched")


def stripe_plan(key: str, solver: str, records: Sequence[int] = RECORDS) -> LoadFactorStripes:
    """The stripes of specimen ``key`` by ``solver``: records 1..n of the paper's suite, each
    run for :data:`DURATION_S` (20 s of record, 5 s after) at the load factors given to
    :func:`rockyade.assess.stripes.run_stripes`; the solver without energy terms and contact states
    (collapse is the question: its runs go to the solver in groups)."""
    if tuple(records) != tuple(range(1, len(records) + 1)):
        raise InputError("records", f"must be the suite's first records 1..n, got {tuple(records)}")
    chosen = as_solver(solver)
    lean = {f: False for f in ("record_energy", "record_contacts") if getattr(chosen, f, False)}
    if lean:  # a single block's collapse reads its status and rotation only
        chosen = dataclasses.replace(chosen, **lean)  # type: ignore[type-var]
    count = len(records)
    ag_s = paper_suite().target.ag_s_m_s2
    return LoadFactorStripes(
        scene_from_dict(_base(key)),
        paper_suite_set(count),
        Measure("pga"),
        (ag_s,) * count,  # lambda = 1: the suite's nominal PGA, ag S
        (DURATION_S,) * count,
        chosen,
        sample_dt_s=SAMPLE_DT_S,
        tail_s=0.0,  # the duration is the run's: the record's 20 s and 5 s after
    )


def tasks(
    specimens=paper.SINGLE_SPECIMENS, records=RECORDS, load_factors=LOAD_FACTORS, solvers=("reference", "housner")
) -> list[StripeTask]:
    """The fragility study's runs (record x load factor, per specimen and solver), as
    :func:`rockyade.assess.stripes.run_stripes` runs them."""
    return [
        task
        for key in specimens
        for solver in solvers
        for task in stripe_plan(key, solver, records).tasks(load_factors)
    ]


def run_runs(
    specimens=paper.SINGLE_SPECIMENS,
    records=RECORDS,
    load_factors=LOAD_FACTORS,
    solvers=("reference", "housner"),
    workers: int = 2,
    desc: str = "fragility",
) -> pd.DataFrame:
    """Run the stripes; one row per run (:data:`rockyade.assess.stripes.RUN_COLUMNS`, the level
    being the load factor) with ``specimen`` (``specimen<key>``) and ``record`` (its number)."""
    frames = []
    executor = Executor("local", workers)
    for key in specimens:
        for solver in solvers:
            print(f"[paper] {desc}: specimen {key}, {SOLVER_LABELS.get(solver, solver)}", flush=True)
            rows = run_stripes(stripe_plan(key, solver, records), list(load_factors), executor)
            frame = pd.DataFrame(rows).drop(columns=["level_si"])
            frame.insert(0, "specimen", f"specimen{key}")
            frame["record"] = frame["record_index"] + 1
            frames.append(frame)
    return pd.concat(frames, ignore_index=True)


def prepare(specimens=paper.SINGLE_SPECIMENS) -> None:
    """Generate the suite (cached; minutes the first time, with a progress bar) and the
    matched calibrations once, before workers fork."""
    suite = paper_suite()
    numbers = range(1, suite.count + 1)
    run_jobs(numbers, lambda i: suite_record(suite, i), progress=True, desc="fragility: synthetic suite")
    for key in specimens:
        calibrated_model(scene_from_dict(_base(key)))


def fit_table(runs: pd.DataFrame) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(stripes, fits): collapses per load factor, and the fitted curves per specimen and solver.

    Parameters
    ----------
    runs
        One row per run: ``specimen``, ``solver``, ``load_factor``, ``status`` (failed runs
        are left out of the stripes and counted), ``collapsed``, ``failure_reason``.
    """
    ag_s = paper_suite().target.ag_s_m_s2
    done = runs[runs.status != "failed"].copy()
    done["collapse"] = done.collapsed.astype(bool)
    stripes = (
        done.groupby(["specimen", "solver", "load_factor"])
        .agg(n_collapse=("collapse", "sum"), n_records=("collapse", "size"))
        .reset_index()
    )
    stripes["pga_m_s2"] = stripes.load_factor * ag_s
    stripes["fraction"] = stripes.n_collapse / stripes.n_records
    fits = []
    for (specimen, solver), group_runs in runs.groupby(["specimen", "solver"]):
        group = stripes[(stripes.specimen == specimen) & (stripes.solver == solver)]
        failed = group_runs[group_runs.status == "failed"]
        reasons = failed.get("failure_reason", pd.Series(dtype=object)).dropna().astype(str)
        reasons = reasons[reasons != ""]
        row = {
            "specimen": specimen,
            "solver": solver,
            "median_pga_m_s2": np.nan,
            "median_load_factor": np.nan,
            "beta": np.nan,
            "status": "",
            "stripes": len(group),
            "largest_tested_pga_m_s2": float(group.pga_m_s2.max()) if len(group) else np.nan,
            "extrapolated": False,
            "runs": len(group_runs),
            "failed_runs": len(failed),
            "failure_reason": reasons.value_counts().index[0] if len(reasons) else "",
        }
        if len(group) < 2:
            row["status"] = f"not fitted: {len(failed)} of {len(group_runs)} runs failed, {len(group)} stripe(s) left"
        else:
            fit = fit_lognormal(group.pga_m_s2, group.n_collapse, group.n_records)
            row.update(
                median_pga_m_s2=fit.median, median_load_factor=fit.median / ag_s, beta=fit.beta, status=fit.status
            )
            # a median above the largest tested intensity is an extrapolation of the fitted curve
            row["extrapolated"] = bool(fit.status == "fitted" and fit.median > row["largest_tested_pga_m_s2"])
        fits.append(row)
    return stripes, pd.DataFrame(fits)


def same_runs_table(runs: pd.DataFrame, solver: str = "yade", reference: str = "reference") -> pd.DataFrame:
    """Per specimen and load factor, on the runs both solvers made (same records): how many
    overturn in each, and in how many runs they agree. The YADE subset's curve is fitted on
    its own few stripes; this table compares the two DEMs run for run."""
    cols = ["specimen", "record", "load_factor"]
    done = runs[runs.status != "failed"]
    a = done[done.solver == solver][[*cols, "status"]]
    b = done[done.solver == reference][[*cols, "status"]]
    both = a.merge(b, on=cols, suffixes=(f"_{solver}", f"_{reference}"))
    if both.empty:
        return pd.DataFrame()
    over_a = both[f"status_{solver}"] == "overturned"
    over_b = both[f"status_{reference}"] == "overturned"
    both = both.assign(a=over_a, b=over_b, same=over_a == over_b)
    table = (
        both.groupby(["specimen", "load_factor"])
        .agg(
            runs=("same", "size"),
            **{f"{solver}_overturned": ("a", "sum"), f"{reference}_overturned": ("b", "sum")},
            same_outcome=("same", "sum"),
        )
        .reset_index()
    )
    return table


def run(report: Report, workers: int = 2, use_yade: bool = True, accel_unit: str = "g") -> pd.DataFrame:
    """Run the fragility batches; write their CSVs and figure (PGA in ``accel_unit``, "g" or
    "m/s2", the other unit on the top axis); return the fits."""
    plan = (
        f"{len(RECORDS)} records x load factors {LOAD_FACTORS[0]}-{LOAD_FACTORS[-1]} per specimen (experimental "
        "parameters, matched calibration), reference DEM and Housner"
    )
    yade_plan = (
        f"YADE on specimen {YADE_SUBSET['specimen']}, records 1-{YADE_SUBSET['records'][-1]}, load factors "
        f"{', '.join(map(str, YADE_SUBSET['load_factors']))}"
    )
    report.section(
        "Collapse fragility over the synthetic suite",
        f"Planned: {plan}; {yade_plan if use_yade else 'YADE off'}. Lognormal curves by maximum likelihood on the "
        "stripes. What ran is stated below.",
    )
    prepare()
    summary = run_runs(workers=workers)
    if use_yade:
        yade = run_runs(
            (YADE_SUBSET["specimen"],),
            YADE_SUBSET["records"],
            YADE_SUBSET["load_factors"],
            ("yade",),
            workers=workers,
            desc="fragility (YADE)",
        )
        summary = pd.concat([summary, yade], ignore_index=True)
    report.record_summary(summary, lambda row: f"{row['specimen']}, record {row['record']} x {row['load_factor']}")
    stripes, fits = fit_table(summary)
    ran = "; ".join(
        f"{SOLVER_LABELS[solver]}: {run_state(report, solver, int((summary.solver == solver).sum()))}"
        for solver in dict.fromkeys(summary.solver)
    )
    report.note(f"Ran: {ran}.")
    extrapolated = fits[fits.extrapolated]
    if len(extrapolated):
        report.note(
            "**Extrapolated medians** (above the largest tested PGA, "
            f"{LOAD_FACTORS[-1]} x ag S = {LOAD_FACTORS[-1] * paper_suite().target.ag_s_m_s2:.3g} m/s^2): "
            + ", ".join(
                f"{r.specimen} by {SOLVER_LABELS[r.solver]} ({fmt(r.median_pga_m_s2, 3)} m/s^2)"
                for r in extrapolated.itertuples()
            )
            + ". The fitted curve is not tested there: read these medians as 'above the tested range'."
        )
    report.table(
        "fragility_runs.csv",
        summary,
        "one row per run: specimen, solver, record, load factor, status, whether the block overturned "
        "(collapsed) and its peak |theta| / alpha.",
    )
    report.table("fragility_stripes.csv", stripes, "collapses / records at each load factor, per specimen and solver.")
    same = same_runs_table(summary) if use_yade else pd.DataFrame()
    if len(same):
        report.table(
            "fragility_yade_vs_reference.csv",
            same,
            "YADE against the reference DEM on the same runs (YADE subset): overturns of each and runs with the "
            "same outcome, per load factor.",
        )
        report.note(
            "YADE and the reference DEM on the same runs: "
            + "; ".join(
                f"x{r.load_factor:g}: {r.yade_overturned} and {r.reference_overturned} of {r.runs} overturn"
                for r in same.itertuples()
            )
            + f"; the same outcome in {int(same.same_outcome.sum())} of {int(same.runs.sum())} runs. Near the "
            "threshold a record's outcome is chaotic (a change of a few 0.1 % decides), so compare the fractions, "
            "not the runs; YADE's curve is fitted on its own few stripes and is the less certain."
        )
    report.table(
        "fragility_fits.csv",
        fits,
        "fitted lognormal fragility: median (PGA and load factor) and beta, "
        "per specimen and solver (YADE: subset, see above).",
    )
    draw_figure(report, stripes, fits, accel_unit)
    return fits


def draw_figure(report: Report, stripes: pd.DataFrame, fits: pd.DataFrame, accel_unit: str = "g") -> Figure:
    """Per specimen: collapse fractions (points), fitted curves (solid over the tested range,
    dotted beyond it), extrapolated medians flagged and missing curves explained; PGA in
    ``accel_unit`` ("g", standard gravity, or "m/s2"), the other unit on the top axis. Each
    panel is a :class:`rockyade.figures.fragility_panels.FragilityDisplay`."""
    name = "fragility.png"
    unit = accel_scale(accel_unit)
    fig, axes = new_figure(report.out / name, 2, 2, figsize=(12, 8.5), sharex=True, sharey=True)
    tested = LOAD_FACTORS[-1] * paper_suite().target.ag_s_m_s2 / unit
    for ax, display in zip(axes.ravel(), fragility_displays(stripes, fits, accel_unit), strict=False):
        display.plot(ax)
    for ax in axes[-1]:  # short: the two bottom labels sit side by side (the caption says the rest)
        ax.set_xlabel(f"PGA of the scaled suite, load factor x ag S ({ACCEL_UNIT_LABELS[accel_unit]})")
    for ax in axes[0]:
        other_accel_axis(ax, accel_unit, "x", "PGA")
    for ax in axes[:, 0]:
        ax.set_ylabel("fraction of records that overturn")
    save_figure(fig, report.out / name)
    notes = _caption_notes(fits, tested, accel_unit)
    report.figure(
        name,
        f"Collapse fragility of the specimens: fraction of the {len(RECORDS)} records that overturn the block "
        "at each load factor (points) and the fitted lognormal curves (solid within the tested PGA, dotted beyond "
        "it, in the grey band; a diamond marks a median beyond the largest tested PGA). The load factor "
        "multiplies the records' accelerations as read." + (" " + "; ".join(notes) + "." if notes else ""),
    )
    return fig


#: Marker of each solver's points.
MARKERS = {"reference": "o", "housner": "s", "yade": "^"}


def fragility_displays(stripes: pd.DataFrame, fits: pd.DataFrame, accel_unit: str = "g") -> list[FragilityDisplay]:
    """One display per specimen (sorted): each solver's stripes and curve in ``accel_unit``."""
    unit = accel_scale(accel_unit)
    tested = LOAD_FACTORS[-1] * paper_suite().target.ag_s_m_s2 / unit
    x_max = 1.35 * tested  # room to show where an extrapolated curve goes
    displays = []
    for specimen in sorted(set(fits.specimen)):
        curves, missing = [], []
        for solver, marker in MARKERS.items():
            sel = fits[(fits.specimen == specimen) & (fits.solver == solver)]
            if sel.empty:
                continue
            fit = sel.iloc[0]
            pts = stripes[(stripes.specimen == specimen) & (stripes.solver == solver)]
            if pts.empty or not fit.status.startswith(("fitted", "no collapse", "all collapse")):
                missing.append(_missing_curve(solver, fit))
                continue
            subset = fit.runs < fits[fits.specimen == specimen].runs.max()
            curves.append(_curve(solver, marker, fit, pts, subset, accel_unit))
        displays.append(
            FragilityDisplay(
                curves,
                x_max,
                ylabel="",
                title=specimen.replace("specimen", "specimen "),
                beyond=tested,
                beyond_text="beyond the largest tested PGA",
                missing=missing,
                ylim=(-0.03, 1.32),  # headroom for the legend above the curves
            )
        )
    return displays


def _curve(solver: str, marker: str, fit, pts: pd.DataFrame, subset: bool, accel_unit: str = "g") -> FragilityCurve:
    """One solver's collapse fractions and fitted curve in ``accel_unit``, its median marked
    when extrapolated; ``subset``: fewer runs than the other solvers (YADE), said in the legend."""
    unit = accel_scale(accel_unit)
    if fit.status == "fitted":
        median = f"median {fmt(fit.median_pga_m_s2 / unit, 3)} {ACCEL_UNIT_LABELS[accel_unit]}"
        if fit.extrapolated:
            median += " EXTRAPOLATED"
        label = f"{SOLVER_LABELS[solver]}: {median}, beta {fmt(fit.beta, 2)}"
    else:
        label = f"{SOLVER_LABELS[solver]}: {fit.status} in the tested range, no fit"
    if fit.failed_runs:
        label += f" ({fit.failed_runs} of {fit.runs} runs failed)"
    elif subset:  # say how small
        label += f" ({int(pts.n_records.max())} records x {len(pts)} load factors)"
    fitted = fit.status == "fitted"
    return FragilityCurve(
        pts.pga_m_s2.to_numpy() / unit,
        pts.fraction.to_numpy(),
        label,
        colour=SOLVER_STYLES[solver]["color"],
        marker=marker,
        fragility=Fragility(fit.median_pga_m_s2 / unit, fit.beta, int(fit.stripes)) if fitted else None,
        tested_max=fit.largest_tested_pga_m_s2 / unit,
        mark_median=bool(fitted and fit.extrapolated),
    )


def _caption_notes(fits: pd.DataFrame, tested: float, accel_unit: str = "g") -> list[str]:
    """What the caption says of extrapolated medians and missing curves (``tested``, the largest
    tested PGA, in ``accel_unit``)."""
    notes = []
    unit = "g" if accel_unit == "g" else "m/s²"  # markdown, not matplotlib's mathtext
    for r in fits.itertuples():
        if r.extrapolated:
            notes.append(f"{r.specimen}, {SOLVER_LABELS[r.solver]}: median extrapolated beyond {fmt(tested, 3)} {unit}")
        if not r.status.startswith(("fitted", "no collapse", "all collapse")):
            notes.append(f"{r.specimen}, {SOLVER_LABELS[r.solver]}: no curve ({r.status}{_reason(r)})")
    return notes


def _missing_curve(solver: str, fit) -> str:
    """Why a solver has no curve, in one legend line."""
    name = SOLVER_LABELS[solver]
    if fit.runs and fit.failed_runs == fit.runs:
        return f"{name}: no curve, all {fit.runs} runs failed" + _reason(fit)
    return f"{name}: no curve, {fit.status}" + _reason(fit)


def _reason(fit, width: int = 40) -> str:
    """The most frequent failure reason, its first clause, for a legend (the CSVs hold it whole)."""
    reason = str(fit.failure_reason or "").split(":")[0].strip()
    return f" ({reason if len(reason) <= width else reason[: width - 3] + '...'})" if reason else ""
