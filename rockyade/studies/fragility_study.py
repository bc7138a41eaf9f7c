"""Collapse fragility of the four specimens over the paper's synthetic suite.

Each specimen (experimental parameters, matched calibration) under the 30 records at load
factors 0.1-1.5 (step 0.1), 25 s (20 s of record, 5 s after): the fraction of records that
overturn it at each load factor, and a lognormal fragility curve fitted by maximum
likelihood, for the reference DEM and Housner; YADE on a documented subset (specimen 2,
records 1-10, load factors 0.4, 0.8, 1.2). Intensity: the nominal PGA of the scaled suite,
load factor x ag S (ag S = 2.8 m/s^2).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from rockyade import paper
from rockyade.batch import expand, run_study_tasks
from rockyade.calibration.model import calibrated_model
from rockyade.constants import ACCEL_UNIT_LABELS
from rockyade.figures import new_figure, save_figure
from rockyade.figures.common import accel_scale, other_accel_axis
from rockyade.figures.styles import SOLVER_LABELS, SOLVER_STYLES
from rockyade.motion.synthetic import paper_suite, suite_record
from rockyade.probability.fragility import Fragility, fit_lognormal
from rockyade.runner import run_jobs
from rockyade.scene import scene_from_dict
from rockyade.studies.report import Report, fmt, run_state
from rockyade.studies.specimens import block_table, scene_dict

LOAD_FACTORS = tuple(round(0.1 * k, 1) for k in range(1, 16))
RECORDS = tuple(range(1, 31))
DURATION_S = 25.0
SAMPLE_DT_S = 0.01
YADE_SUBSET = {"specimen": "2", "records": tuple(range(1, 11)), "load_factors": (0.4, 0.8, 1.2)}


def _base(key: str) -> dict:
    motion = {"type": "synthetic", "suite": "paper", "record": 1, "load_factor": 1.0}
    return scene_dict([block_table(key)], motion, DURATION_S, SAMPLE_DT_S, "matched")


def tasks(
    out, specimens=paper.SINGLE_SPECIMENS, records=RECORDS, load_factors=LOAD_FACTORS, solvers=("reference", "housner")
):
    """Batch tasks of the fragility study."""
    bases = [(f"specimen{key}", _base(key)) for key in specimens]
    grid = {"motion.record": list(records), "motion.load_factor": list(load_factors)}
    return expand(bases, grid, solvers, save_history=False)


def prepare(specimens=paper.SINGLE_SPECIMENS) -> None:
    """Generate the suite (cached; minutes the first time, with a progress bar) and the
    matched calibrations once, before workers fork."""
    suite = paper_suite()
    numbers = range(1, suite.count + 1)
    run_jobs(numbers, lambda i: suite_record(suite, i), progress=True, desc="fragility: synthetic suite")
    for key in specimens:
        calibrated_model(scene_from_dict(_base(key)))


def fit_table(summary: pd.DataFrame) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(stripes, fits): collapses per load factor, and the fitted curves per specimen and solver."""
    ag_s = paper_suite().target.ag_s_m_s2
    done = summary[summary.status != "failed"].copy()
    done["collapse"] = done.status == "overturned"
    stripes = (
        done.groupby(["base", "solver", "motion.load_factor"])
        .agg(n_collapse=("collapse", "sum"), n_records=("collapse", "size"))
        .reset_index()
    )
    stripes = stripes.rename(columns={"base": "specimen", "motion.load_factor": "load_factor"})
    stripes["pga_m_s2"] = stripes.load_factor * ag_s
    stripes["fraction"] = stripes.n_collapse / stripes.n_records
    fits = []
    for (specimen, solver), runs in summary.groupby(["base", "solver"]):
        group = stripes[(stripes.specimen == specimen) & (stripes.solver == solver)]
        failed = runs[runs.status == "failed"]
        reasons = failed.get("failure_reason", pd.Series(dtype=object)).dropna().astype(str)
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
            "runs": len(runs),
            "failed_runs": len(failed),
            "failure_reason": reasons.value_counts().index[0] if len(reasons) else "",
        }
        if len(group) < 2:
            row["status"] = f"not fitted: {len(failed)} of {len(runs)} runs failed, {len(group)} stripe(s) left"
        else:
            fit = fit_lognormal(group.pga_m_s2, group.n_collapse, group.n_records)
            row.update(
                median_pga_m_s2=fit.median, median_load_factor=fit.median / ag_s, beta=fit.beta, status=fit.status
            )
            # a median above the largest tested intensity is an extrapolation of the fitted curve
            row["extrapolated"] = bool(fit.status == "fitted" and fit.median > row["largest_tested_pga_m_s2"])
        fits.append(row)
    return stripes, pd.DataFrame(fits)


def same_runs_table(summary: pd.DataFrame, solver: str = "yade", reference: str = "reference") -> pd.DataFrame:
    """Per specimen and load factor, on the runs both solvers made (same records): how many
    overturn in each, and in how many runs they agree. The YADE subset's curve is fitted on
    its own few stripes; this table compares the two DEMs run for run."""
    cols = ["base", "motion.record", "motion.load_factor"]
    done = summary[summary.status != "failed"]
    a = done[done.solver == solver][[*cols, "status"]]
    b = done[done.solver == reference][[*cols, "status"]]
    both = a.merge(b, on=cols, suffixes=(f"_{solver}", f"_{reference}"))
    if both.empty:
        return pd.DataFrame()
    over_a = both[f"status_{solver}"] == "overturned"
    over_b = both[f"status_{reference}"] == "overturned"
    both = both.assign(a=over_a, b=over_b, same=over_a == over_b)
    table = (
        both.groupby(["base", "motion.load_factor"])
        .agg(
            runs=("same", "size"),
            **{f"{solver}_overturned": ("a", "sum"), f"{reference}_overturned": ("b", "sum")},
            same_outcome=("same", "sum"),
        )
        .reset_index()
        .rename(columns={"base": "specimen", "motion.load_factor": "load_factor"})
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
    runs = report.out / "fragility_runs"
    summary = run_study_tasks(tasks(runs), runs, workers=workers, desc="fragility", resume_option=None)
    if use_yade:
        subset = tasks(
            report.out / "fragility_yade_runs",
            (YADE_SUBSET["specimen"],),
            YADE_SUBSET["records"],
            YADE_SUBSET["load_factors"],
            ("yade",),
        )
        yade_summary = run_study_tasks(
            subset, report.out / "fragility_yade_runs", workers=workers, desc="fragility (YADE)", resume_option=None
        )
        summary = pd.concat([summary, yade_summary], ignore_index=True)
    report.record_summary(
        summary, lambda row: f"{row['base']}, record {row['motion.record']} x {row['motion.load_factor']}"
    )
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
    ``accel_unit`` ("g", standard gravity, or "m/s2"), the other unit on the top axis."""
    specimens = sorted(set(fits.specimen))
    name = "fragility.png"
    unit = accel_scale(accel_unit)
    fig, axes = new_figure(report.out / name, 2, 2, figsize=(12, 8.5), sharex=True, sharey=True)
    tested = LOAD_FACTORS[-1] * paper_suite().target.ag_s_m_s2 / unit
    x_max = 1.35 * tested  # room to show where an extrapolated curve goes
    x = np.linspace(0.05 / unit, x_max, 300)
    markers = {"reference": "o", "housner": "s", "yade": "^"}
    for ax, specimen in zip(axes.ravel(), specimens, strict=False):
        missing = []
        for solver, marker in markers.items():
            sel = fits[(fits.specimen == specimen) & (fits.solver == solver)]
            if sel.empty:
                continue
            fit = sel.iloc[0]
            pts = stripes[(stripes.specimen == specimen) & (stripes.solver == solver)]
            if pts.empty or not fit.status.startswith(("fitted", "no collapse", "all collapse")):
                missing.append(_missing_curve(solver, fit))
                continue
            subset = fit.runs < fits[fits.specimen == specimen].runs.max()
            _draw_fit(ax, solver, marker, fit, pts, subset, x, x_max, accel_unit)
        ax.axvspan(tested, x_max, color="0.92", lw=0, zorder=0)
        ax.text(
            x_max,
            0.5,
            "beyond the largest tested PGA ",
            rotation=90,
            fontsize=6.5,
            color="0.4",
            ha="right",
            va="center",
        )
        for text in missing:  # a legend entry, so that it never covers the points
            ax.plot([], [], ls="none", marker="x", color="#b2182b", label=text)
        ax.set_title(specimen.replace("specimen", "specimen "))
        ax.set_xlim(0, x_max)
        ax.set_ylim(-0.03, 1.32)  # headroom for the legend above the curves
        ax.set_yticks(np.linspace(0, 1, 6))
        ax.grid(alpha=0.3)
        legend = ax.legend(fontsize=7, loc="upper left")  # curves rise to the right: that corner is free
        for text in legend.get_texts():
            if "no curve" in text.get_text():
                text.set_color("#b2182b")
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


def _draw_fit(
    ax,
    solver: str,
    marker: str,
    fit,
    pts: pd.DataFrame,
    subset: bool,
    x: np.ndarray,
    x_max: float,
    accel_unit: str = "g",
) -> None:
    """One solver's collapse fractions (points) and fitted curve (solid within its tested
    range, dotted beyond), its median marked when extrapolated; ``subset``: fewer runs than
    the other solvers (YADE), said in the legend. ``x`` and ``x_max`` in ``accel_unit``."""
    colour = SOLVER_STYLES[solver]["color"]
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
    ax.plot(pts.pga_m_s2 / unit, pts.fraction, marker, color=colour, ms=4.5, label=label, mfc="none", mew=1.2)
    if fit.status != "fitted":
        return
    curve = Fragility(fit.median_pga_m_s2 / unit, fit.beta, int(fit.stripes)).probability(x)
    inside = x <= fit.largest_tested_pga_m_s2 / unit
    ax.plot(x[inside], curve[inside], color=colour, lw=1.3)
    ax.plot(x[~inside], curve[~inside], color=colour, lw=1.3, ls=":")
    if fit.extrapolated:  # the median on the dotted curve (an arrow at the edge when beyond it)
        inside_plot = fit.median_pga_m_s2 / unit <= x_max
        ax.plot(
            min(fit.median_pga_m_s2 / unit, x_max),
            0.5,
            "D" if inside_plot else ">",
            color=colour,
            mfc="white",
            ms=6,
            mew=1.3,
            zorder=5,
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
