"""Uncertainty of alpha, p, mu propagated through the paper's synthetic suite (Housner solver).

Part 1, sensitivity (the paper's conclusion "small variations of alpha, p, mu produce large
differences in the response"): specimens 1-4, experimental parameters as nominal; alpha, p,
mu either (a) uniform within +/-5 % (independent) or (b) the joint normal of an
identification of a free-rocking test of that specimen (200 Hz, noise 0.5 % of alpha,
release at alpha / 2, 8 s; rockyade's own identify); 20 Latin hypercube samples and the
nominal block, every sample under the 30 records at load factors 0.4-1.4. Reported per
specimen and load factor: P(overturn) of the nominal block, the 5-95 % range of the
per-sample P(overturn), the fraction of records whose outcome (overturn or not) depends on
the sample, and the spread factor of the peak theta/alpha of a record (q95 / q05 across
samples, median over the records that rock).

Part 2, convergence of a fragility: specimen 2, +/-5 % uniform, one record per sample
(drawn by the hypercube), load factors 0.2-1.5; lognormal fits against PGA / (g tan alpha)
and PGV with N = 25, 50, 100, 200, 400 samples, three seeds each; a figure.

    .venv/bin/python benchmarks/bench_uncertainty.py [--out reports/bench_uncertainty] [--quick]
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib import colormaps

from rockyade import paper
from rockyade.figures.canvas import file_figure, save_figure
from rockyade.identification.fit import identify, synthetic_measurement
from rockyade.io.atomic import atomic_open, write_json
from rockyade.probability.fragility_curves import Fragility
from rockyade.studies.uncertainty import run_uncertainty, uncertainty_study_from_dict

SENSITIVITY_LOAD_FACTORS = [0.4, 0.6, 0.8, 1.0, 1.2, 1.4]
CONVERGENCE_LOAD_FACTORS = [round(0.1 * k, 1) for k in range(2, 16)]
CONVERGENCE_SAMPLES = (25, 50, 100, 200, 400)
CONVERGENCE_SEEDS = (1, 2, 3)
#: --quick, whose numbers mean nothing (the script must only run through): specimen 1 (the same
#: path as 1-4), 2 samples, 2 records and 3 load factors, a free-rocking test of 4 s identified,
#: N = 4 and 8 at 4 load factors, in threads (a process pool per study cost more than its runs),
#: no figure per study
QUICK_SENSITIVITY = {
    "specimens": ("1",),
    "samples": 2,
    "records": [1, 2],
    "load_factors": [0.6, 1.0, 1.4],
    "identified_s": 4.0,
}
QUICK_CONVERGENCE = {"sizes": (4, 8), "seeds": (1,), "load_factors": [0.2, 0.6, 1.0, 1.4]}
MEASURES = ["pga_over_g_tan_alpha", "pgv_m_s", "pga_m_s2", "pgv_p_over_g_tan_alpha", "arias_m_s"]


def _uniform(values: dict[str, float], pct: float) -> dict:
    return {k: {"distribution": "uniform", "mean": v, "plus_minus_pct": pct} for k, v in values.items()}


def _identified(key: str, out: Path, duration_s: float = 8.0) -> Path:
    """An identification of a synthetic free-rocking test of the specimen, written as JSON."""
    e = paper.specimen(key).experimental
    history = synthetic_measurement(
        e["alpha_rad"],
        e["p_rad_s"],
        e["mu"],
        theta0_rad=0.5 * e["alpha_rad"],
        rate_hz=200.0,
        duration_s=duration_s,
        hold_s=0.5,
        release_offset_s=0.0021,
        offset_rad=0.002,
        noise_rad=0.005 * e["alpha_rad"],
        seed=int(key),
    )
    path = out / f"specimen{key}_identified.json"
    write_json(path, identify(history).as_dict())
    return path


def _study(
    key: str, parameters: dict, samples: int, seed: int, load_factors, pairing: str, records="all", nominal: bool = True
) -> dict:
    return {
        "name": f"specimen{key}",
        "solvers": ["housner"],
        "samples": samples,
        "seed": seed,
        "duration_s": 25.0,
        "sample_dt_s": 0.01,
        "nominal": nominal,
        "theta_over_alpha_levels": [0.5, 1.0],
        "intensity_measures": MEASURES,
        "block": {"specimen": key},
        "parameters": parameters,
        "motion": {"suite": "paper", "records": records, "load_factors": load_factors, "pairing": pairing},
    }


def sensitivity(
    out: Path,
    samples: int,
    records,
    load_factors=SENSITIVITY_LOAD_FACTORS,
    executor="local",
    figure=True,
    identified_s=8.0,
    specimens=paper.SINGLE_SPECIMENS,
) -> pd.DataFrame:
    rows = []
    for key in specimens:
        ident_path = _identified(key, out, identified_s)
        ident = json.loads(ident_path.read_text())
        cases = {
            "+/-5 % uniform": _uniform(paper.specimen(key).experimental, 5.0),
            "identification": {"identified": ident_path.name},
        }
        for case, parameters in cases.items():
            study = uncertainty_study_from_dict(
                _study(key, parameters, samples, 100 + int(key), load_factors, "all", records),
                str(out / "study.toml"),
                out,
            )
            start = time.perf_counter()
            folder = out / "sensitivity" / f"specimen{key}_{'pm5' if case.startswith('+') else 'identified'}"
            result = run_uncertainty(study, folder, executor=executor, workers=2, progress=False, figure=figure)
            seconds = time.perf_counter() - start
            spread = result.spread.copy()
            spread.insert(0, "case", case)
            spread.insert(0, "specimen", key)
            spread["alpha_ci_pct"] = 50 * (ident["alpha_rad_ci"][1] - ident["alpha_rad_ci"][0]) / ident["alpha_rad"]
            spread["seconds"] = seconds
            spread["runs"] = len(result.runs)
            rows.append(spread)
            for row in spread.itertuples(index=False):
                factor = row.theta_spread_factor
                # NaN: no record rocks in every sample (spread_table), so there is no ratio to show
                shown = f"x{factor:.2f}" if math.isfinite(factor) else "- (no record rocks in every sample)"
                print(
                    f"  specimen {key} {case:15s} x{row.load_factor:<4g} nominal P {row.p_overturn_nominal:.3f}; "
                    f"per-sample P {row.p_overturn_sample_q05:.3f}-{row.p_overturn_sample_q95:.3f}; "
                    f"records with mixed outcome {100 * row.records_mixed_fraction:3.0f} %; "
                    f"peak theta/alpha spread {shown}"
                )
            extra = f"; identified alpha +/-{spread['alpha_ci_pct'].iloc[0]:.2f} %" if case == "identification" else ""
            print(f"  ({len(result.runs)} runs in {seconds:.0f} s{extra})")
    table = pd.concat(rows, ignore_index=True)
    with atomic_open(out / "sensitivity.csv") as fh:
        table.to_csv(fh, index=False, float_format="%.6g", lineterminator="\n")
    return table


def convergence(out: Path, sizes, seeds, load_factors=CONVERGENCE_LOAD_FACTORS, executor="local") -> pd.DataFrame:
    key = "2"
    rows = []
    for n in sizes:
        for seed in seeds:
            study = uncertainty_study_from_dict(
                _study(
                    key,
                    _uniform(paper.specimen(key).experimental, 5.0),
                    n,
                    seed,
                    load_factors,
                    "sampled",
                    nominal=False,
                )
            )
            result = run_uncertainty(
                study,
                out / "convergence" / f"n{n}_seed{seed}",
                executor=executor,
                workers=2,
                progress=False,
                figure=False,
            )
            for fit in result.fragility.itertuples(index=False):
                rows.append(
                    {
                        "samples": n,
                        "seed": seed,
                        "runs": len(result.runs),
                        "measure": fit.measure,
                        "median": fit.median,
                        "beta": fit.beta,
                        "status": fit.status,
                        "n_overturned": fit.n_overturned,
                    }
                )
    table = pd.DataFrame(rows)
    with atomic_open(out / "fragility_convergence.csv") as fh:
        table.to_csv(fh, index=False, float_format="%.6g", lineterminator="\n")
    for measure in ("pga_over_g_tan_alpha", "pgv_m_s"):
        sel = table[table.measure == measure]
        ref = sel[sel.samples == sel.samples.max()]
        ref_median, ref_beta = ref["median"].mean(), ref["beta"].mean()
        n_max = sel.samples.max()
        print(f"  {measure}: reference (N = {n_max}, mean of seeds) median {ref_median:.4g}, beta {ref_beta:.3g}")
        for n, g in sel.groupby("samples"):
            print(
                f"    N = {n:4d}: median {g['median'].mean():.4g} "
                f"(seeds {g['median'].min():.4g}-{g['median'].max():.4g}), "
                f"beta {g['beta'].mean():.3g} ({g['beta'].min():.3g}-{g['beta'].max():.3g}); "
                f"max |median / reference - 1| {100 * np.max(np.abs(g['median'] / ref_median - 1)):.1f} %"
            )
    _convergence_figure(table, out / "fragility_convergence.png", len(load_factors))
    return table


def _convergence_figure(table: pd.DataFrame, path: Path, n_load_factors: int) -> None:
    fig, axes = file_figure(1, 3, figsize=(15, 4.4))
    measure = "pga_over_g_tan_alpha"
    sel = table[table.measure == measure]
    for seed, g in sel.groupby("seed"):
        axes[0].semilogx(g.samples, g["median"], "o-", ms=4, label=f"seed {seed}")
        axes[1].semilogx(g.samples, g["beta"], "o-", ms=4, label=f"seed {seed}")
    sizes = sorted(sel.samples.unique())
    for ax, name in ((axes[0], "median PGA / (g tan alpha)"), (axes[1], "beta (log standard deviation)")):
        ax.set_xticks(sizes, [str(n) for n in sizes])
        ax.minorticks_off()
        ax.set_xlabel(f"samples N (one record each, x {n_load_factors} load factors)")
        ax.set_ylabel(name)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    x = np.linspace(0.05, 3.0, 300)
    for k, (n, g) in enumerate(sel[sel.seed == sel.seed.min()].groupby("samples")):
        row = g.iloc[0]
        if row.status == "fitted":
            axes[2].plot(
                x,
                Fragility(row["median"], row["beta"], 0).probability(x),
                color=colormaps["viridis"](k / 5),
                label=f"N = {n}",
            )
    axes[2].set_xlabel("PGA / (g tan alpha)")
    axes[2].set_ylabel("P(overturn)")
    axes[2].set_title("fitted fragility, first seed", fontsize=9)
    axes[2].grid(alpha=0.3)
    axes[2].legend(fontsize=8)
    fig.suptitle("Specimen 2, alpha, p, mu uniform +/-5 %, synthetic suite: convergence of the fragility", fontsize=10)
    save_figure(fig, path)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("reports/bench_uncertainty"))
    parser.add_argument("--quick", action="store_true", help="a few runs of each part (QUICK_*), to see it runs")
    parser.add_argument("--only", choices=["sensitivity", "convergence"])
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    full = {"samples": 20, "records": "all", "load_factors": SENSITIVITY_LOAD_FACTORS}
    sens = {**QUICK_SENSITIVITY, "executor": "threads", "figure": False} if args.quick else full
    full = {"sizes": CONVERGENCE_SAMPLES, "seeds": CONVERGENCE_SEEDS, "load_factors": CONVERGENCE_LOAD_FACTORS}
    conv = {**QUICK_CONVERGENCE, "executor": "threads"} if args.quick else full
    start = time.perf_counter()
    if args.only in (None, "sensitivity"):
        print("sensitivity of specimens 1-4 (Housner, synthetic suite):")
        sensitivity(args.out, **sens)
    if args.only in (None, "convergence"):
        print("fragility convergence (specimen 2):")
        convergence(args.out, **conv)
    print(f"wrote {args.out} in {time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
