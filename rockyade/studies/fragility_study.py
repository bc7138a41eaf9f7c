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

from rockyade import paper
from rockyade.analysis.fragility import fit_lognormal
from rockyade.dem.matching import build_matched_model
from rockyade.figures import plt, save_figure
from rockyade.motion.synthetic import generate_suite, paper_suite
from rockyade.scene import scene_from_dict
from rockyade.studies.batch import expand, run_study_tasks
from rockyade.studies.common import Report, block_table, fmt, scene_dict

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
    return expand(bases, grid, solvers, out, save_history=False)


def prepare(specimens=paper.SINGLE_SPECIMENS) -> None:
    """Generate the suite and the matched calibrations once, before workers fork."""
    generate_suite(paper_suite())
    for key in specimens:
        build_matched_model(scene_from_dict(_base(key)))


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
    for (specimen, solver), group in stripes.groupby(["specimen", "solver"]):
        fit = fit_lognormal(group.pga_m_s2, group.n_collapse, group.n_records)
        fits.append(
            {
                "specimen": specimen,
                "solver": solver,
                "median_pga_m_s2": fit.median,
                "median_load_factor": fit.median / ag_s,
                "beta": fit.beta,
                "status": fit.status,
                "stripes": fit.n_points,
                "failed_runs": int(
                    ((summary.base == specimen) & (summary.solver == solver) & (summary.status == "failed")).sum()
                ),
            }
        )
    return stripes, pd.DataFrame(fits)


def run(report: Report, workers: int = 2, use_yade: bool = True) -> pd.DataFrame:
    """Run the fragility batches; write their CSVs and figure; return the fits."""
    report.section(
        "Collapse fragility over the synthetic suite",
        f"{len(RECORDS)} records x load factors {LOAD_FACTORS[0]}-{LOAD_FACTORS[-1]} per specimen (experimental "
        "parameters, matched calibration), reference DEM and Housner; YADE on specimen "
        f"{YADE_SUBSET['specimen']}, records 1-{YADE_SUBSET['records'][-1]}, load factors "
        f"{', '.join(map(str, YADE_SUBSET['load_factors']))}. Lognormal curves by maximum likelihood on the stripes.",
    )
    prepare()
    runs = report.out / "fragility_runs"
    summary = run_study_tasks(tasks(runs), runs, workers=workers, desc="fragility")
    if use_yade:
        subset = tasks(
            report.out / "fragility_yade_runs",
            (YADE_SUBSET["specimen"],),
            YADE_SUBSET["records"],
            YADE_SUBSET["load_factors"],
            ("yade",),
        )
        yade_summary = run_study_tasks(
            subset, report.out / "fragility_yade_runs", workers=workers, desc="fragility (YADE)"
        )
        summary = pd.concat([summary, yade_summary], ignore_index=True)
    stripes, fits = fit_table(summary)
    report.table("fragility_stripes.csv", stripes, "collapses / records at each load factor, per specimen and solver.")
    report.table(
        "fragility_fits.csv",
        fits,
        "fitted lognormal fragility: median (PGA and load factor) and beta, "
        "per specimen and solver (YADE: subset, see above).",
    )
    _figure(report, stripes, fits)
    return fits


def _figure(report: Report, stripes: pd.DataFrame, fits: pd.DataFrame) -> None:
    specimens = sorted(stripes.specimen.unique())
    fig, axes = plt.subplots(2, 2, figsize=(11, 8), sharex=True, sharey=True)
    x = np.linspace(0.05, 1.6 * 2.8, 300)
    styles = {"reference": ("C1", "o"), "housner": ("C0", "s"), "yade": ("C2", "^")}
    for ax, specimen in zip(axes.ravel(), specimens, strict=False):
        for solver, (colour, marker) in styles.items():
            pts = stripes[(stripes.specimen == specimen) & (stripes.solver == solver)]
            if pts.empty:
                continue
            fit = fits[(fits.specimen == specimen) & (fits.solver == solver)].iloc[0]
            label = f"{solver}: median {fmt(fit.median_pga_m_s2, 3)} m/s$^2$, beta {fmt(fit.beta, 2)}"
            ax.plot(pts.pga_m_s2, pts.fraction, marker, color=colour, ms=4, label=label)
            if fit.status == "fitted":
                from rockyade.analysis.fragility import Fragility

                ax.plot(
                    x, Fragility(fit.median_pga_m_s2, fit.beta, int(fit.stripes)).probability(x), color=colour, lw=1.2
                )
        ax.set_title(specimen.replace("specimen", "specimen "))
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="lower right")
    for ax in axes[-1]:
        ax.set_xlabel("PGA of the scaled suite, load factor x ag S (m/s$^2$)")
    for ax in axes[:, 0]:
        ax.set_ylabel("fraction of records that overturn")
    name = "fragility.png"
    save_figure(fig, report.out / name)
    report.figure(
        name,
        "Collapse fragility of the four specimens: fraction of the 30 records that overturn the block "
        "at each load factor (points) and the fitted lognormal curves (lines).",
    )
